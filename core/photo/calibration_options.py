"""The options of camera calibration (:mod:`.camera_calibration`): its parameter names and
choices, kept apart from the adjustment (scipy) so that the algorithm's spec reads its
defaults without importing it (core/jobs/calibrate_camera.py)."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError
from ..geometry.projection_names import PROJECTIONS

INTERIOR_NAMES = ("focal_mm", "x0_mm", "y0_mm", "k1", "k2", "k3", "p1", "p2")
LENS_NAMES = INTERIOR_NAMES[3:]
FIELD_MODES = ("fixed", "free")
#: Lens models of the calibration: the photogrammetric Brown-Conrady correction (measured ->
#: ideal, :class:`core.geometry.distortion.BrownConrady`) or OpenCV's and COLMAP's forward
#: distortion (ideal -> measured, :class:`core.geometry.forward_lens.OpenCVLens`), both with
#: the coefficients k1 k2 k3 p1 p2.
LENS_MODELS = ("brown_conrady", "opencv")


@dataclass(frozen=True)
class CalibrationOptions:
    """Options of :func:`~.camera_calibration.calibrate_camera`.

    Attributes
    ----------
    projection : str
        ``"perspective"`` or a fisheye projection (:data:`core.geometry.projection.PROJECTIONS`).
    lens_model : {"brown_conrady", "opencv"}
        The lens model (:data:`LENS_MODELS`): ``opencv`` adjusts OpenCV's own model, so that
        the result is the same least-squares problem as ``cv2.calibrateCamera`` with a fixed
        aspect ratio and can be used by OpenCV or COLMAP without conversion (perspective
        projection only).
    lens_parameters : tuple of str
        Lens coefficients to estimate (the others are held at zero), of
        ``k1 k2 k3 p1 p2``.
    field : {"fixed", "free"}
        Target coordinates as given (fixed) or estimated with a minimal datum (free).
    sigma_px : float
        A-priori standard deviation of a detected point, pixels (each coordinate).
    alpha : float
        Significance level of the t-tests of the lens coefficients.
    max_iterations : int
        Of the adjustment.
    """

    projection: str = "perspective"
    lens_model: str = "brown_conrady"
    lens_parameters: tuple[str, ...] = LENS_NAMES
    field: str = "fixed"
    sigma_px: float = 0.2
    alpha: float = 0.05
    max_iterations: int = 100

    def __post_init__(self) -> None:
        """Check the choices (raises :class:`InputError`)."""
        if self.projection not in PROJECTIONS:
            raise InputError(
                f"projection must be one of {', '.join(PROJECTIONS)}, got {self.projection!r}"
            )
        if self.lens_model not in LENS_MODELS:
            raise InputError(
                f"lens model must be one of {', '.join(LENS_MODELS)}, got {self.lens_model!r}"
            )
        if self.lens_model == "opencv" and self.projection != "perspective":
            raise InputError(
                "the opencv lens model is OpenCV's perspective model: use it with the "
                f"perspective projection (got {self.projection!r}), or brown_conrady"
            )
        bad = [p for p in self.lens_parameters if p not in LENS_NAMES]
        if bad:
            raise InputError(f"unknown lens parameter(s) {bad}: use some of {list(LENS_NAMES)}")
        if self.field not in FIELD_MODES:
            raise InputError(f"field must be fixed or free, got {self.field!r}")
        if not self.sigma_px > 0:
            raise InputError(f"sigma_px must be positive, got {self.sigma_px}")


#: Kinds of planar calibration target (:mod:`.calibration_targets` detects them).
TARGET_KINDS: tuple[str, ...] = ("chessboard", "charuco", "aruco")
#: OpenCV's predefined ArUco dictionaries accepted by name.
DICTIONARIES: tuple[str, ...] = (
    "DICT_4X4_50",
    "DICT_4X4_100",
    "DICT_4X4_250",
    "DICT_4X4_1000",
    "DICT_5X5_50",
    "DICT_5X5_100",
    "DICT_5X5_250",
    "DICT_5X5_1000",
    "DICT_6X6_50",
    "DICT_6X6_100",
    "DICT_6X6_250",
    "DICT_6X6_1000",
    "DICT_7X7_50",
    "DICT_7X7_100",
    "DICT_7X7_250",
    "DICT_7X7_1000",
    "DICT_ARUCO_ORIGINAL",
    "DICT_APRILTAG_16h5",
    "DICT_APRILTAG_25h9",
    "DICT_APRILTAG_36h10",
    "DICT_APRILTAG_36h11",
)


@dataclass(frozen=True)
class TargetSpec:
    """Geometry of a planar calibration target.

    Parameters
    ----------
    kind : {"chessboard", "charuco", "aruco"}
    cols, rows : int
        chessboard: inner corners per row and per column; charuco: squares in x and y;
        aruco: markers in x and y.
    spacing_m : float
        chessboard and charuco: the square side; aruco: the marker side; metres.
    marker_m : float
        charuco: the marker side; aruco: the gap between markers; metres (unused for a
        chessboard).
    dictionary : str
        ArUco dictionary (charuco, aruco), one of :data:`DICTIONARIES`.
    """

    kind: str = "chessboard"
    cols: int = 9
    rows: int = 6
    spacing_m: float = 0.025
    marker_m: float = 0.0
    dictionary: str = "DICT_6X6_250"

    def __post_init__(self) -> None:
        """Check the kind, the counts and the sizes (raises :class:`InputError`)."""
        if self.kind not in TARGET_KINDS:
            raise InputError(f"target kind must be one of {', '.join(TARGET_KINDS)}")
        if self.cols < 2 or self.rows < 2:
            raise InputError(
                f"a {self.kind} target needs at least 2 x 2 (got {self.cols} x {self.rows})"
            )
        if not self.spacing_m > 0:
            raise InputError(f"the target spacing must be positive, got {self.spacing_m}")
        if self.kind == "charuco" and not 0 < self.marker_m < self.spacing_m:
            raise InputError(
                "a ChArUco marker must be smaller than the square "
                f"({self.marker_m} m vs {self.spacing_m} m)"
            )
        if self.kind == "aruco" and not self.marker_m > 0:
            raise InputError("an ArUco grid board needs the gap between markers (marker_m > 0)")
        if self.kind != "chessboard" and self.dictionary not in DICTIONARIES:
            raise InputError(f"unknown ArUco dictionary {self.dictionary!r}")
