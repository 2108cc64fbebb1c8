"""core/io/images.read_gray: every image as 8-bit grey with its contrast kept (a 16-bit or
12-bit frame stretched, not divided by 256), reduced while decoding."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.io.images import read_gray


def _frame(dtype, low: float, high: float) -> np.ndarray:
    img = np.full((64, 96), low, dtype)
    img[:, 48:] = high  # one vertical edge
    return img


@pytest.mark.parametrize(
    "dtype,low,high",
    [(np.uint16, 700, 850), (np.uint16, 0, 4095), (np.uint8, 40, 200), (np.float32, 0.25, 0.5)],
)
@pytest.mark.parametrize("factor", [1, 2])
def test_the_edge_keeps_its_contrast(tmp_path, dtype, low, high, factor):
    """A 150 DN edge of a 16-bit frame (0.6 DN once divided by 256, lost in rounding) is
    stretched over the 8 bits; 8-bit images are read as they are."""
    path = tmp_path / "frame.tif"
    assert cv2.imwrite(str(path), _frame(dtype, low, high))
    img = read_gray(path, factor)
    assert img.dtype == np.uint8 and img.shape == (64 // factor, 96 // factor)
    left, right = int(img[:, : 20 // factor].mean()), int(img[:, -20 // factor :].mean())
    if dtype == np.uint8:
        assert (left, right) == (low, high)
    else:
        assert (left, right) == (0, 255)


def test_a_missing_file_is_named(tmp_path):
    with pytest.raises(InputError, match="image file not found"):
        read_gray(tmp_path / "none.tif")
