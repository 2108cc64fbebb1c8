"""The options of the automatic boresight calibration (:mod:`.auto_boresight`) and of its
line observations (:mod:`.auto_lines`), in a module that imports no numerical library, so that
the command line's help reads their defaults without the science (tests/core/test_startup.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import InputError
from .tie_options import TiePointOptions

__all__ = ["AutoBoresightOptions", "AutoLineOptions", "calibration_ties"]


def calibration_ties() -> TiePointOptions:
    """The tie points of the automatic calibration: the ``tiepoints`` recipe before
    2026-12-04 (4,000 features of contrast 0.02 detected at up to 3,000 px, 64 FLANN checks,
    measurements the least-squares matching refused kept at their keypoints), with which its
    figures in bench/auto_boresight.md were measured."""
    return TiePointOptions(
        max_features=4000,
        contrast=0.02,
        max_dimension_px=3000,
        checks=64,
        refine_keep_unrefined=True,
    )


@dataclass(frozen=True)
class AutoLineOptions:
    """Parameters of :func:`line_observations` (pixels unless said).

    spacing_px: distance between samples along a projected line.
    search_px: half width of the search across the line (>= the projection's uncertainty
        from the pose's, e.g. 3 sigma).
    along_px: half length of the stretch of edge averaged per sample.
    min_contrast: smallest grey step across an accepted edge (grey units of the image).
    ambiguity: a second gradient peak above this fraction of the first refuses the sample.
    min_points: fewest accepted samples a line must keep.
    margin_px: samples nearer the frame border than this are dropped.
    outlier_sigmas: refusal threshold on the per-line fit's robust residual sigma.
    segment_sigmas: an image's segment of a line whose offset is farther than this many robust
        sigmas from the displacement the image's other segments give (shift, rotation and
        scale of the image: its pose error) is on another edge and is dropped.
    segment_min_px: floor of that robust sigma, pixels (the model's misfit).
    min_sigma_px: floor of the reported sigma (the fit's RMS can be tiny on few points).
    max_samples: most samples of one line in one image (a long line's samples are spread
        wider than ``spacing_px``): the boresight is bound by the INS priors long before, and
        the adjustment's time (data snooping) grows with the observations (a 24-Mpx flight).
    """

    spacing_px: float = 4.0
    search_px: float = 4.0
    along_px: float = 2.0
    min_contrast: float = 4.0
    ambiguity: float = 0.6
    min_points: int = 5
    margin_px: float = 2.0
    outlier_sigmas: float = 3.0
    min_sigma_px: float = 0.05
    segment_sigmas: float = 3.0
    segment_min_px: float = 1.0
    max_samples: int = 100

    def __post_init__(self) -> None:
        for name in (
            "spacing_px",
            "search_px",
            "min_sigma_px",
            "outlier_sigmas",
            "segment_sigmas",
            "segment_min_px",
        ):
            if not float(getattr(self, name)) > 0:
                raise InputError(f"{name} must be > 0, got {getattr(self, name)!r}")
        for name in ("along_px", "min_contrast", "margin_px"):
            if not float(getattr(self, name)) >= 0:
                raise InputError(f"{name} must be >= 0, got {getattr(self, name)!r}")
        if not 0 < float(self.ambiguity) <= 1:
            raise InputError(f"ambiguity must be in (0, 1], got {self.ambiguity!r}")
        if int(self.max_samples) < int(self.min_points):
            raise InputError(f"max_samples must be >= min_points, got {self.max_samples!r}")
        if int(self.min_points) < 3:
            raise InputError(f"min_points must be >= 3, got {self.min_points!r}")


@dataclass(frozen=True)
class AutoBoresightOptions:
    """Parameters of :func:`auto_calibrate`.

    search_deg: half width of the angle search about the initial boresight, degrees (0: no
        search, the initial boresight must be within a few pixels).
    coarse_step_px, fine_step_px: first and last grid step of the search, pixels in the image
        (the first is widened to an eighth of the search range when that is larger: large
        images take as many candidates as small ones).
    min_search_px: smallest half width of the edge search across a projected line, pixels.
    sigmas: width of the edge search and of the tie gate in standard deviations.
    min_gate_m: smallest tie gate, metres.
    border_m: smallest distance of a tie from its plane's outline, metres.
    max_roof_slope_deg: steeper planes are walls (no tie), degrees.
    min_slope_deg: a plane sloping less is flat (does not make the angles observable), degrees.
    min_line_directions: fewest distinct line directions (15 degrees apart in plan) that make
        the angles observable without sloped planes.
    max_rounds: most association-adjustment rounds.
    find_ties: without tie points given, find them between the images (the ``tiepoints``
        chain with ``ties``: pairs from the footprints, least-squares refinement) when the
        planes have outlines.
    segment_sigma_px: first round's sigma of a line segment's (one line in one image) common
        offset and tilt across the line, pixels; later rounds use the variances estimated from
        the round before (:mod:`.boresight_weights`; 0: the points weighted as independent).
    lines: options of the edge search (its ``search_px`` is set per round).
    ties: options of the tie points found (FIND_TIES): :func:`calibration_ties`, not the
        ``tiepoints`` defaults, whose recipe for COLMAP's yield (16,384 features detected at
        2,000 px) cost the demo's 4 images 910 s of CPU, 6 rounds without convergence and an
        angle 3.0 sigma off, against 110 s, converged, within 1.71 sigma with these
        (2026-12-04; the calibration needs the ties on roof planes, about 2 % of the tracks,
        not long tracks).
    """

    search_deg: float = 1.0
    coarse_step_px: float = 8.0
    fine_step_px: float = 0.5
    min_search_px: float = 2.5
    sigmas: float = 3.0
    min_gate_m: float = 0.05
    border_m: float = 0.3
    max_roof_slope_deg: float = 65.0
    min_slope_deg: float = 5.0
    min_line_directions: int = 2
    max_rounds: int = 6
    find_ties: bool = True
    segment_sigma_px: float = 0.3
    lines: AutoLineOptions = field(default_factory=AutoLineOptions)
    ties: TiePointOptions = field(default_factory=lambda: calibration_ties())

    def __post_init__(self) -> None:
        for name in ("coarse_step_px", "fine_step_px", "min_search_px", "sigmas", "min_gate_m"):
            if not float(getattr(self, name)) > 0:
                raise InputError(f"{name} must be > 0, got {getattr(self, name)!r}")
        if not 0 <= float(self.search_deg) <= 10:
            raise InputError(f"search_deg must be in [0, 10] degrees, got {self.search_deg!r}")
        if self.fine_step_px > self.coarse_step_px:
            raise InputError("fine_step_px must not exceed coarse_step_px")
        if not float(self.segment_sigma_px) >= 0:
            raise InputError(f"segment_sigma_px must be >= 0, got {self.segment_sigma_px!r}")
        if int(self.max_rounds) < 1 or int(self.min_line_directions) < 1:
            raise InputError("max_rounds and min_line_directions must be >= 1")
