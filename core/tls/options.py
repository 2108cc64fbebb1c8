"""Options of the TLS self-calibration (:func:`~.calibration.calibrate`), in a module of their
own so that the job's parameter spec can take its defaults without importing the solver."""

from __future__ import annotations

from dataclasses import dataclass

from .ap_table import ARCSEC

__all__ = ["CalibrationOptions"]


@dataclass(frozen=True)
class CalibrationOptions:
    """Options of :func:`calibrate`.

    Attributes
    ----------
    ap_set : str or tuple of str
        ``"none"`` (registration only), ``"paper"`` (a0, b1, b2, c0), ``"extended"``
        (Lichti's physical set) or a list of terms (:mod:`.aps`).
    levelled : bool
        Default for stations whose table does not say: the compensator levelled the scanner,
        so omega and phi are observed (with ``tilt_sigma_rad``); otherwise they are free.
    tilt_sigma_rad : float
        Standard deviation of the compensator's omega and phi (radians).
    cyclic_wavelength_m : float
        Modulation wavelength U of the cyclic range terms a2, a3 (metres).
    datum : {"inner", "reference"}
        Without control: ``"inner"`` constrains the free targets as a whole (minimum
        constraints: their mean position and mean orientation stay those of the approximate
        registration; only the rotation about the vertical when a station is levelled, whose
        compensator defines the tilt), so that the standard deviations and correlations do not
        depend on one station (free-network adjustment); ``"reference"`` holds the
        reference station at its pose (position and kappa, also omega and phi when it is not
        levelled).
    reference_station : str or None
        Station that defines the frame when there is no control: the approximate
        registration starts from it (at its given pose, else the origin), and with
        ``datum="reference"`` it is held there (default: the first station of the stations
        table with a position, else the first station observed).
    snooping, snooping_alpha : bool, float
        Baarda data snooping (whole observations) and its significance per observation.
    significance_alpha : float
        Two-sided level of the Student-t test of each AP.
    correlation_limit : float
        Correlations (absolute) at or above this are reported as strong, and in
        ``select_aps`` a pair of APs beyond it loses one member.
    select_aps : bool
        Choose the APs by significance and correlation (backward elimination from
        ``ap_set``).
    max_iterations : int
        Of each adjustment.
    """

    ap_set: str | tuple[str, ...] = "paper"
    levelled: bool = True
    tilt_sigma_rad: float = 10.0 * ARCSEC
    cyclic_wavelength_m: float = 1.2
    datum: str = "inner"
    reference_station: str | None = None
    snooping: bool = True
    snooping_alpha: float = 0.001
    significance_alpha: float = 0.05
    correlation_limit: float = 0.9
    select_aps: bool = False
    max_iterations: int = 50
