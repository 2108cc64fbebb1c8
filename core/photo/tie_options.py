"""Settings of the tie-point chain (:func:`lidarphoto.core.photo.tie_points.tie_points`), apart
from its OpenCV and SciPy code so that the algorithm's parameters are read without them."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError

__all__ = ["DETECTORS", "KEEP_MODES", "PAIR_MODES", "RANSAC_METHODS", "TiePointOptions"]

DETECTORS = ("sift", "orb")
#: Which ``max_features`` keypoints SIFT keeps: the largest scales, or the strongest.
KEEP_MODES = ("scale", "response")
#: ``auto``: footprints when an orientation is given, else the sequential window.
PAIR_MODES = ("auto", "footprints", "all", "sequential")
RANSAC_METHODS = ("magsac", "ransac")


@dataclass(frozen=True)
class TiePointOptions:
    """Settings of :func:`tie_points` (units in the names).

    detector : "sift" or "orb"
    max_features : int
        Keypoints kept per image (which ones: ``keep``). 16,384 by default (COLMAP's
        keypoint count at its 8,192: 6 kite images, 3,795 three-image tracks against its
        3,662-3,730; 4,000 before 2026-12-04: 1,190; bench/matching.md).
    contrast : float
        SIFT's contrast threshold (OpenCV's ``contrastThreshold``, divided by the 3 layers
        per octave: grey levels / 255; OpenCV's default 0.04). Lower finds weaker extrema;
        ``max_features`` are kept either way (see ``keep``), so a low threshold fills the
        budget on low-contrast images instead of stopping short of it (6 kite images at
        8,192 features: 0.04 finds 5,116 per image, 0.02 fills the budget; 0.01 by default,
        which finds more at the reduced detection size).
    keep : one of :data:`KEEP_MODES`
        SIFT: which ``max_features`` keypoints are kept when more are found: ``"scale"``
        those of the largest scale (COLMAP's rule; fine-scale extrema are many and repeat
        less between views), ``"response"`` the strongest (OpenCV's). ORB: the strongest.
    max_dimension_px : int
        Features are detected on the image reduced by the smallest integer factor that
        brings its longer side to at most this; 0 detects at full resolution. 2,000 by
        default: images of 2,001-4,000 px at half size, where OpenCV's doubled first octave
        is the full image's octave 0 (the largest scales kept come from octaves >= 0 at
        full size: the same keypoints for a quarter of the detection's CPU).
    checks : int
        SIFT: leaves of FLANN's k-d trees visited per nearest-neighbour search (the search's
        cost grows with it; fewer finds fewer true neighbours). 24 by default: 6 kite
        images at 16,384 features, 64 checks 3,980 three-image tracks, 24 3,849, for 60 %
        less matching CPU (bench/matching.md).
    ratio : float
        Lowe's ratio: best distance / second best must be below it.
    root_sift : bool
        SIFT: match RootSIFT descriptors (L1-normalised, square-rooted; Arandjelovic &
        Zisserman 2012; COLMAP's default) rather than OpenCV's raw ones.
    mutual : bool
        Keep a match only if it is also the best in the other direction.
    ransac_px : float
        RANSAC threshold on the distance to the epipolar line, full-resolution pixels.
    ransac_method : "magsac" (MAGSAC++) or "ransac"
    guided : bool
        SIFT: after the fundamental matrix, every keypoint is matched again among its
        nearest descriptors that lie within ``ransac_px`` of its epipolar line (ratio test
        among those): the matches the global ratio test lost to look-alikes elsewhere in the
        image. On by default (6 kite images at 16,384 features: +5 % verified matches, +8 %
        three-image tracks; bench/matching.md).
    preemptive : float
        SIFT, pixels verified by the fundamental matrix: the share of an image's keypoints
        (the largest scales) a pair is first tried on; fewer than ``min_inliers`` inliers
        there and the pair is dropped without searching the rest (0: off; only where the
        share holds at least 1,000 keypoints, i.e. from 8,000 features at 1/8). 6 kite
        images, all 15 pairs, 16,384 features: the 6 pairs without overlap dropped at an eighth
        of their search, the 9 others unchanged (bench/matching.md).
    min_inliers : int
        Fewer inliers: the pair is dropped.
    min_track_length : int
        Images a track must span.
    pair_mode : one of :data:`PAIR_MODES`
    window : int
        Sequential mode: each image is matched with the next ``window`` images.
    min_overlap : float
        Footprint mode: overlap / smaller footprint area at least this.
    sigma_px : float
        A-priori sigma written with every measurement, pixels; 0 = 0.5 px times the
        detection reduction factor.
    coherence : float
        Motion coherence: an inlier whose displacement (what a homography fitted robustly
        to the pair leaves of it) differs from the median displacement of its 8 nearest
        inliers by more than this share of the image diagonal is dropped
        (0: no test). It removes wrong matches that slide along the epipolar line, which
        the fundamental matrix cannot see (aerial strips: all epipolar lines are parallel).
    refine : bool
        Least-squares refinement of the tracks (:func:`refine_tracks`); on by default: it
        cuts the median error 1.2-3.6x for +25 to +40 % CPU (bench/matching.md, "Tie points").
    refine_half_px : int
        Half size of the LSM template, full-resolution pixels (template 2 h + 1 square).
    refine_sigma_floor_px : float
        Smallest sigma_px written for a refined measurement (the LSM sigma ignores the
        model errors of the affine patch model, e.g. relief inside the patch).
    refine_keep_unrefined : bool
        A measurement the least-squares matching ran on and refused without calling it
        another point (the patch left its window, no convergence, no texture, sigma too
        large) is kept at its keypoint (True) or dropped (False, the default since
        2026-12-04: on the simulated block at 1,500 features, 5 -> 1 wrong tracks of 4,400,
        all of them such measurements). Measurements it could not try (template at the image
        border, no start affine) are kept either way.
    """

    detector: str = "sift"
    max_features: int = 16384
    contrast: float = 0.01
    keep: str = "scale"
    max_dimension_px: int = 2000
    ratio: float = 0.8
    checks: int = 24
    root_sift: bool = True
    mutual: bool = True
    ransac_px: float = 2.0
    ransac_method: str = "magsac"
    guided: bool = True
    preemptive: float = 0.125
    min_inliers: int = 15
    min_track_length: int = 2
    pair_mode: str = "auto"
    window: int = 5
    min_overlap: float = 0.05
    sigma_px: float = 0.0
    coherence: float = 0.03
    refine: bool = True
    refine_half_px: int = 10
    refine_sigma_floor_px: float = 0.02
    refine_keep_unrefined: bool = False

    def __post_init__(self) -> None:
        if self.detector not in DETECTORS:
            raise InputError(f"detector must be one of {', '.join(DETECTORS)}")
        if self.keep not in KEEP_MODES:
            raise InputError(f"keep must be one of {', '.join(KEEP_MODES)}")
        if self.pair_mode not in PAIR_MODES:
            raise InputError(f"pair mode must be one of {', '.join(PAIR_MODES)}")
        if self.ransac_method not in RANSAC_METHODS:
            raise InputError(f"RANSAC method must be one of {', '.join(RANSAC_METHODS)}")
        if not 0.0 < self.ratio <= 1.0:
            raise InputError(f"ratio must be in (0, 1], got {self.ratio:g}")
        if self.checks < 1:
            raise InputError(f"FLANN checks must be at least 1, got {self.checks}")
        if self.min_track_length < 2:
            raise InputError("a track needs at least 2 images")
        if self.min_inliers < 8:
            raise InputError("the fundamental matrix needs at least 8 inliers")
        if not 0.0 < self.contrast < 1.0:
            raise InputError(f"SIFT contrast threshold must be in (0, 1), got {self.contrast:g}")
        if not 0.0 <= self.preemptive < 1.0:
            raise InputError(f"preemptive share must be in [0, 1), got {self.preemptive:g}")
        if self.refine_half_px < 3:
            raise InputError("the refinement template needs a half size of at least 3 px")
