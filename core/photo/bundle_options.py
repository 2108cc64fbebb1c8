"""The options of a bundle adjustment (:mod:`.bundle`), in a module of their own that imports
no numerical library beyond the AP families' table, so that the command line's help reads their
defaults without the adjustment's engine (tests/core/test_startup.py)."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError
from ..geometry.ap_families import AP_FAMILIES

#: Datum definitions of :class:`BundleOptions` (``datum``).
DATUMS = ("control", "inner", "minimal")
#: Robust reweightings of :class:`BundleOptions` (``robust``), those of `core.lsq.outliers`.
ROBUSTS = ("none", "huber", "cauchy")


@dataclass(frozen=True)
class BundleOptions:
    """Options of :func:`~.bundle.bundle_adjust`.

    Attributes
    ----------
    ap_model : str
        AP family for every camera: a key of
        :data:`~lidarphoto.core.geometry.ap_models.AP_FAMILIES` (``none`` holds the camera's
        lens model fixed).
    estimate_interior : bool
        Estimate the principal distance and the principal point of every camera.
    ap_selection : bool
        Drop insignificant APs one at a time and re-adjust: an AP goes only when its own
        t-test and, with the insignificant APs it correlates with above ``max_correlation``,
        a joint F-test find it insignificant (a correlation alone never drops one).
    ap_alpha : float
        Two-sided significance level of the AP t-test.
    max_correlation : float
        |correlation| above which a pair of interior parameters is flagged (and, with
        selection, the correlated insignificant APs are tested jointly).
    robust : str
        ``none``, ``huber`` or ``cauchy``: reweighting before data snooping.
    snooping : bool
        Baarda data snooping.
    snooping_alpha : float
        Significance level per observation of data snooping.
    datum : str
        ``control`` (control points and/or observed orientations), ``inner`` (free network,
        inner constraints on the tie points) or ``minimal`` (free network, seven parameters
        held); with scale bars a free network keeps six (the bars give the scale).
    estimate_mount : bool
        With observed orientations: estimate a common lever-arm correction (camera axes,
        metres) and boresight correction (about the camera axes) between the observed and
        the adjusted orientations, signed as in docs/conventions.md, "Rotations":
        ``X_pc = X_obs + R_c^m da``,
        ``R_c^m = R_obs dR`` (a boresight calibration's dR).
    estimate_timing : bool
        With observed orientations: estimate a constant camera timing offset dt (seconds,
        exposure = recorded time + dt), the observed centre being the GNSS/INS position at
        the recorded time, ``X_obs = X_pc - R_c^m da - v dt``, with each exposure's velocity
        ``v`` from the EO table (v_north, v_east, v_up or vx, vy, vz) or differenced from the
        neighbouring exposures of its group (:mod:`.timing`). It needs velocities that vary
        across the block (strips in different directions or at different speeds) or ground
        control; with the lever arm, camera-frame velocities that vary (different speeds).
    max_iterations : int
        Iterations of each adjustment.
    covariance : bool
        Compute the covariance (sigmas, t-tests, w-tests); needed by the AP selection and
        data snooping (off only for speed measurements).
    """

    ap_model: str = "none"
    estimate_interior: bool = True
    ap_selection: bool = True
    ap_alpha: float = 0.05
    max_correlation: float = 0.9
    robust: str = "huber"
    snooping: bool = True
    snooping_alpha: float = 0.001
    datum: str = "control"
    estimate_mount: bool = False
    estimate_timing: bool = False
    max_iterations: int = 60
    covariance: bool = True

    def __post_init__(self) -> None:
        if self.ap_model not in AP_FAMILIES:
            raise InputError(f"AP model '{self.ap_model}' is not one of {', '.join(AP_FAMILIES)}")
        if self.datum not in DATUMS:
            raise InputError(f"datum '{self.datum}' is not one of {', '.join(DATUMS)}")
        if not 0 < self.ap_alpha < 1 or not 0 < self.max_correlation <= 1:
            raise InputError("ap_alpha must be in (0, 1) and max_correlation in (0, 1]")
