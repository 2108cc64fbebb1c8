"""The options of the boresight calibration (:mod:`.boresight`), in a module of their own that
imports no numerical library, so that the command line's help reads their defaults without the
adjustment's engine (tests/core/test_startup.py)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Union

if TYPE_CHECKING:
    from .ins import InsGrade


@dataclass(frozen=True)
class BoresightOptions:
    """Options of :func:`~.boresight.calibrate`.

    Attributes
    ----------
    groups : str or mapping
        ``"single"`` one boresight for all images; ``"group"`` one per value of the
        trajectory's group column (flight line, direction or session, as the user filled it);
        ``"direction"`` one per compass octant of the heading (N, NE, ...); or a mapping
        image_id -> group name.
    estimate_lever_arm, estimate_interior : bool
        Add the lever arm (3) / the focal length and principal point (3) as unknowns.
    ins_grade : str or InsGrade
        Key of :data:`INS_GRADES` or a custom grade: sigmas of the INS prior observations.
    ins_as_parameters : bool
        True: INS positions and attitudes are nuisance parameters with their priors. False: held at
        the INS values (weighted with 1e-6 times the grade's sigmas), as Pedrosa & dos Santos
        (2020).
    roof_roughness_m : float
        Standard deviation of a roof point about its plane (tiles, sag), metres (> 0).
    use_types : tuple of str
        Observation types used (``tie``, ``line``, ``lcp``, ``paper``, ``control``).
    paper_sigma : {"eq17", "propagated"}
        Standard deviation of d in paper mode (module docstring).
    lidar_sigma_m : float
        Nominal LiDAR coordinate sigma of Eq. 17, metres.
    paper_z_neighbours : int
        LiDAR points of the plane whose mean height is the paper's z.
    estimate_timing : bool
        Add a constant camera timing offset dt (seconds, exposure = recorded time + dt) as an
        unknown: the INS position prior becomes ``p_ins(t) = p(t + dt) - v(t) dt`` with v the
        trajectory's velocity at the exposure (its v_north, v_east, v_up columns, as
        ``importtrajectory`` writes them) or, without them, finite differences of neighbouring
        exposures of the same flight line (:func:`.boresight_setup.exposure_velocity`; then >=
        2 images per line). With the lever arm also estimated, lines at clearly different
        speeds are needed (else refused as not observable).
    snooping, snooping_alpha : bool, float
        Baarda data snooping and its significance per observation.
    snooping_per_group : bool
        Snooping's significance per group instead (a LiDAR line's points are one group: see
        ``AdjustmentOptions.snooping_per_group``); the automatic calibration's setting.
    max_iterations : int
    line_segment_sigmas_px : (float, float)
        Standard deviations (pixels) of the error that the points of one LiDAR line in one
        image share (a segment): its offset across the line and its tilt (the offset's change
        from the segment's middle to its end). Each segment gets the two as nuisance
        unknowns with these priors, i.e. its points' covariance carries the common part (edge
        model against the LiDAR line, seen from that image). (0, 0): none (hand picks: each
        point independent); the automatic calibration estimates them from the residuals.
    """

    groups: Union[str, Mapping[str, str]] = "group"
    estimate_lever_arm: bool = False
    estimate_interior: bool = False
    ins_grade: Union[str, InsGrade] = "pos_av_310"
    ins_as_parameters: bool = True
    roof_roughness_m: float = 0.01
    use_types: tuple[str, ...] = ("tie", "line", "lcp", "paper", "control")
    paper_sigma: str = "eq17"
    lidar_sigma_m: float = 0.05
    paper_z_neighbours: int = 4
    estimate_timing: bool = False
    snooping: bool = True
    snooping_alpha: float = 0.001
    max_iterations: int = 50
    line_segment_sigmas_px: tuple[float, float] = (0.0, 0.0)
    snooping_per_group: bool = False
