"""What the tie-point stages hand each other: an image's keypoints and descriptors, and the
verified matches of one pair."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["ImageFeatures", "PairMatch"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ImageFeatures:
    """Keypoints of one image (full-resolution pixels, project convention).

    Attributes
    ----------
    image_id : str
    size_px : (int, int)
        Width and height of the full image.
    factor : int
        Reduction factor of the detection image (1: full resolution).
    pixels : (N, 2) float64
        col, row of each keypoint, pixels of the full image (centre of the first pixel 0.5).
    scale_px : (N,) float32
        Keypoint diameter, full-resolution pixels.
    descriptors : (N, D) uint8
        SIFT (D = 128) or ORB (D = 32 bytes).
    """

    image_id: str
    size_px: tuple[int, int]
    factor: int
    pixels: Array
    scale_px: NDArray[np.float32]
    descriptors: NDArray[np.uint8]

    def __len__(self) -> int:
        return int(self.pixels.shape[0])


@dataclass(frozen=True)
class PairMatch:
    """Result of matching one pair (indices into the two images' keypoints).

    ``status`` is ``ok`` or the reason the pair was dropped; ``residual_px`` is the
    symmetric distance of each inlier to its epipolar lines (full-resolution pixels, the mean
    of the two images' distances).
    """

    i: int
    j: int
    idx_i: NDArray[np.intp]
    idx_j: NDArray[np.intp]
    n_ratio: int
    n_mutual: int
    n_inliers: int
    residual_px: Array
    status: str
    overlap: float = math.nan

    @property
    def kept(self) -> bool:
        return self.status == "ok"
