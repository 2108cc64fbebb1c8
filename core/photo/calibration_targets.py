"""Planar calibration targets: their fields of points and their detection in images (OpenCV).

Three targets, each a *field* of points with integer ids and nominal coordinates in the
target's plane (metres, ``Z = 0``; X along the target's columns, Y along its rows):

- **chessboard**: ``cols x rows`` inner corners (OpenCV counts inner corners), spacing the
  square side; id ``= row * cols + col``. Found by ``cv2.findChessboardCornersSB`` (the
  sector-based detector, sub-pixel by design), falling back to ``cv2.findChessboardCorners``
  + ``cv2.cornerSubPix``.
- **charuco**: a ChArUco board of ``squares_x x squares_y`` squares with ArUco markers in the
  white squares; the field is the chessboard corners, with OpenCV's ChArUco corner ids
  (``cv2.aruco.CharucoDetector``, then ``cv2.cornerSubPix``: OpenCV 4.11's ChArUco corners
  lie 0.5 px off the true ones on a rendered board).
- **aruco**: an ArUco grid board of ``markers_x x markers_y`` markers; the field is the four
  corners of every marker, id ``= 4 * marker_id + corner`` (corner 0..3: OpenCV's order,
  top-left, top-right, bottom-right, bottom-left of the marker), refined to sub-pixel
  (``cv2.aruco.ArucoDetector`` with ``CORNER_REFINE_SUBPIX``).

Detections are returned in the project's pixel convention (origin at the top-left corner of
the top-left pixel, :mod:`core.geometry.camera`): OpenCV puts the centre of the first pixel at
``(0, 0)``, so 0.5 px is added to both coordinates.

Science functions take images as numpy arrays (grey or BGR); reading files is the job's.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Tuple

import numpy as np
from numpy.typing import NDArray

from .calibration_options import DICTIONARIES, TARGET_KINDS, TargetSpec  # noqa: F401 - the old address

Array = NDArray[np.float64]

# OpenCV pixel centres are integers; the project's are at +0.5.
_CV_TO_PROJECT_PX = 0.5


@dataclass(frozen=True)
class TargetField:
    """The points of a target: ``ids`` (M,) int and nominal ``xyz`` (M, 3) metres (Z = 0).

    ``datum`` holds three ids (origin, a point along X, a point off that line) that fix the
    datum of a free field (:mod:`core.photo.camera_calibration`).
    """

    ids: NDArray[np.int64]
    xyz: Array
    datum: Tuple[int, int, int]
    spacing_m: float

    def coordinates(self, ids: NDArray[np.int64]) -> Array:
        """Nominal coordinates (N, 3) of ``ids`` (KeyError for an unknown id)."""
        lookup = {int(i): k for k, i in enumerate(self.ids)}
        return self.xyz[[lookup[int(i)] for i in ids]]


@dataclass(frozen=True)
class Detection:
    """Target points found in one image: ``ids`` (n,) and ``pixels`` (n, 2) (col, row)."""

    image: str
    ids: NDArray[np.int64]
    pixels: Array


def _dictionary(name: str) -> Any:
    import cv2

    return cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, name))


def _charuco_board(spec: TargetSpec) -> Any:
    import cv2

    return cv2.aruco.CharucoBoard(
        (spec.cols, spec.rows), spec.spacing_m, spec.marker_m, _dictionary(spec.dictionary)
    )


def _grid_board(spec: TargetSpec) -> Any:
    import cv2

    return cv2.aruco.GridBoard(
        (spec.cols, spec.rows), spec.spacing_m, spec.marker_m, _dictionary(spec.dictionary)
    )


def target_field(spec: TargetSpec) -> TargetField:
    """The field of points of a target (ids and nominal coordinates, metres).

    >>> f = target_field(TargetSpec("chessboard", cols=3, rows=2, spacing_m=0.5))
    >>> f.ids.tolist(), f.datum
    ([0, 1, 2, 3, 4, 5], (0, 2, 3))
    >>> f.xyz[:, :2].tolist()
    [[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [0.0, 0.5], [0.5, 0.5], [1.0, 0.5]]
    """
    if spec.kind == "chessboard":
        c, r = np.meshgrid(np.arange(spec.cols), np.arange(spec.rows))
        grid = np.column_stack([c.ravel(), r.ravel(), np.zeros(c.size)])
        xyz = np.asarray(grid * spec.spacing_m, dtype=np.float64)  # float64 already: no copy
        ids = np.arange(spec.cols * spec.rows, dtype=np.int64)
        return TargetField(
            ids, xyz, (0, spec.cols - 1, (spec.rows - 1) * spec.cols), spec.spacing_m
        )
    if spec.kind == "charuco":
        corners = np.asarray(_charuco_board(spec).getChessboardCorners(), dtype=np.float64)
        nc, nr = spec.cols - 1, spec.rows - 1
        ids = np.arange(corners.shape[0], dtype=np.int64)
        return TargetField(ids, corners.reshape(-1, 3), (0, nc - 1, (nr - 1) * nc), spec.spacing_m)
    board = _grid_board(spec)
    obj = np.asarray(board.getObjPoints(), dtype=np.float64).reshape(-1, 4, 3)
    mids = np.asarray(board.getIds(), dtype=np.int64).ravel()
    ids = (4 * mids[:, None] + np.arange(4)[None, :]).ravel()
    last_in_row = 4 * int(mids[spec.cols - 1]) + 1
    first_of_last = 4 * int(mids[(spec.rows - 1) * spec.cols]) + 3
    return TargetField(
        ids, obj.reshape(-1, 3), (int(ids[0]), last_in_row, first_of_last), spec.spacing_m
    )


def _grey(image: NDArray[Any]) -> NDArray[np.uint8]:
    import cv2

    img = np.asarray(image)
    if img.ndim == 3:
        img = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
    if img.dtype != np.uint8:
        lo, hi = float(np.nanmin(img)), float(np.nanmax(img))
        img = np.clip((img - lo) * (255.0 / max(hi - lo, 1e-12)), 0, 255).astype(np.uint8)
    return img


def detect_target(image: NDArray[Any], spec: TargetSpec, name: str = "") -> Detection:
    """Find the target's points in one image (grey or BGR array).

    Returns a :class:`Detection` with no points when the target is not found (a chessboard is
    found whole or not at all; ChArUco and ArUco boards may be partly visible).
    """
    import cv2

    grey = _grey(image)
    if spec.kind == "chessboard":
        pattern = (spec.cols, spec.rows)
        ok, corners = cv2.findChessboardCornersSB(
            grey, pattern, flags=cv2.CALIB_CB_EXHAUSTIVE | cv2.CALIB_CB_ACCURACY
        )
        if not ok:
            ok, corners = cv2.findChessboardCorners(
                grey, pattern, flags=cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
            )
            if ok:
                crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 1e-3)
                corners = cv2.cornerSubPix(grey, corners, (5, 5), (-1, -1), crit)
        if not ok:
            return Detection(name, np.zeros(0, np.int64), np.zeros((0, 2)))
        px = np.asarray(corners, dtype=np.float64).reshape(-1, 2) + _CV_TO_PROJECT_PX
        return Detection(name, np.arange(px.shape[0], dtype=np.int64), px)
    if spec.kind == "charuco":
        det = cv2.aruco.CharucoDetector(_charuco_board(spec))
        corners, ids, _, _ = det.detectBoard(grey)
        if ids is None or len(ids) == 0:
            return Detection(name, np.zeros(0, np.int64), np.zeros((0, 2)))
        # CharucoDetector's corners sit 0.5 px off those of cornerSubPix and of the
        # chessboard detectors on a synthetic board (see the tests): refine them again.
        crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 1e-3)
        corners = cv2.cornerSubPix(grey, np.asarray(corners, np.float32), (4, 4), (-1, -1), crit)
        px = np.asarray(corners, dtype=np.float64).reshape(-1, 2) + _CV_TO_PROJECT_PX
        return Detection(name, np.asarray(ids, dtype=np.int64).ravel(), px)
    params = cv2.aruco.DetectorParameters()
    params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    board = _grid_board(spec)
    aruco = cv2.aruco.ArucoDetector(_dictionary(spec.dictionary), params)
    marker_corners, ids, _ = aruco.detectMarkers(grey)
    if ids is None or len(ids) == 0:
        return Detection(name, np.zeros(0, np.int64), np.zeros((0, 2)))
    mids = np.asarray(ids, dtype=np.int64).ravel()
    on_board = np.isin(mids, np.asarray(board.getIds()).ravel())
    c = np.asarray(marker_corners, dtype=np.float64).reshape(-1, 4, 2)[on_board]
    mids = mids[on_board]
    # a marker id seen twice in one image is ambiguous: drop it
    uniq, counts = np.unique(mids, return_counts=True)
    keep = np.isin(mids, uniq[counts == 1])
    pid = (4 * mids[keep, None] + np.arange(4)[None, :]).ravel()
    return Detection(name, pid, c[keep].reshape(-1, 2) + _CV_TO_PROJECT_PX)
