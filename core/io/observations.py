"""Image observations for boresight calibration: the CSV table and its in-memory form.

One row per measurement of a point in one image (header row; names case-insensitive)::

    image_id,point_id,col,row,sigma_px,type,target_id

image_id
    The image, as in the trajectory table.
point_id
    Name of the measured point. For ``tie`` it names the tie point: every row with the same
    ``point_id`` is the same ground point seen in another image. For the other types it only
    labels the row (it may repeat across images).
col, row
    Measured pixel position: origin at the top-left corner of the top-left pixel, so the
    centre of the first pixel is (0.5, 0.5); columns grow to the right, rows downwards.
sigma_px
    A-priori standard deviation of col and row, pixels (> 0). Empty: 0.5 px.
type
    ``tie``   a roof point measured in two or more images, lying on plane ``target_id``;
    ``line``  a point anywhere on the LiDAR line ``target_id`` (ridge, hip or valley);
    ``lcp``   the LiDAR control point ``target_id`` (three-plane intersection);
    ``paper`` a point on plane ``target_id`` for the single-image model of paper 000 (its
              Eqs. 12-17);
    ``check`` the LiDAR control point ``target_id`` used only as a check point (not adjusted).
target_id
    Id of the plane, line or LCP in its table (integers in the project's tables).

Errors name the file, the row (the header is row 1) and the column. The image-picking dock
writes the same table.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from .tables import find_column, float_column, read_table, text_column, write_csv_atomic

__all__ = [
    "DEFAULT_SIGMA_PX",
    "OBSERVATION_COLUMNS",
    "OBSERVATION_TYPES",
    "ImageObservations",
    "read_observations_csv",
    "write_observations_csv",
]

OBSERVATION_COLUMNS = ("image_id", "point_id", "col", "row", "sigma_px", "type", "target_id")
OBSERVATION_TYPES = ("tie", "line", "lcp", "paper", "check")
DEFAULT_SIGMA_PX = 0.5

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ImageObservations:
    """N image measurements (see the module docstring for the meaning of each field).

    Attributes
    ----------
    image_id, point_id, type, target_id : tuple of str, shape (N,)
    pixels : ndarray, shape (N, 2)
        (col, row) in pixels.
    sigma_px : ndarray, shape (N,)
        Standard deviation of col and row, pixels.
    """

    image_id: tuple[str, ...]
    point_id: tuple[str, ...]
    pixels: Array
    sigma_px: Array
    type: tuple[str, ...]
    target_id: tuple[str, ...]

    def __post_init__(self) -> None:
        n = len(self.image_id)
        px = np.asarray(self.pixels, dtype=np.float64).reshape(-1, 2)
        sig = np.broadcast_to(np.asarray(self.sigma_px, dtype=np.float64), (n,)).copy()
        object.__setattr__(self, "pixels", px)
        object.__setattr__(self, "sigma_px", sig)
        for name in ("image_id", "point_id", "type", "target_id"):
            object.__setattr__(self, name, tuple(str(v) for v in getattr(self, name)))
        if not all(len(getattr(self, k)) == n for k in ("point_id", "type", "target_id")) or (
            px.shape[0] != n
        ):
            raise InputError("image observations: all fields must have the same length")
        bad = sorted(set(self.type) - set(OBSERVATION_TYPES))
        if bad:
            raise InputError(
                f"unknown observation type(s) {bad}; use one of {', '.join(OBSERVATION_TYPES)}"
            )
        if not (np.isfinite(px).all() and np.isfinite(sig).all() and (sig > 0).all()):
            raise InputError("image observations: pixels must be finite and sigma_px > 0")

    def __len__(self) -> int:
        return len(self.image_id)

    @classmethod
    def from_arrays(
        cls,
        image_id: Sequence[str],
        point_id: Sequence[str],
        pixels: ArrayLike,
        sigma_px: ArrayLike,
        type: Sequence[str],
        target_id: Sequence[object],
    ) -> ImageObservations:
        """Build from sequences (ids are converted to text)."""
        return cls(
            tuple(map(str, image_id)),
            tuple(map(str, point_id)),
            np.asarray(pixels, dtype=np.float64),
            np.asarray(sigma_px, dtype=np.float64),
            tuple(map(str, type)),
            tuple(map(str, target_id)),
        )

    def mask(self, kind: str) -> NDArray[np.bool_]:
        """(N,) rows of one observation type."""
        return np.array([t == kind for t in self.type], dtype=bool)

    def subset(self, keep: ArrayLike) -> ImageObservations:
        """Rows selected by a boolean mask or an index array."""
        idx = np.arange(len(self))[np.asarray(keep)]
        return ImageObservations(
            tuple(self.image_id[i] for i in idx),
            tuple(self.point_id[i] for i in idx),
            self.pixels[idx],
            self.sigma_px[idx],
            tuple(self.type[i] for i in idx),
            tuple(self.target_id[i] for i in idx),
        )

    def concat(self, other: ImageObservations) -> ImageObservations:
        """Rows of ``self`` followed by those of ``other``."""
        return ImageObservations(
            self.image_id + other.image_id,
            self.point_id + other.point_id,
            np.vstack([self.pixels, other.pixels]),
            np.concatenate([self.sigma_px, other.sigma_px]),
            self.type + other.type,
            self.target_id + other.target_id,
        )


def read_observations_csv(path: Union[str, Path]) -> ImageObservations:
    """Read the observation table (format in the module docstring).

    Raises
    ------
    InputError
        Missing columns, non-numeric or non-positive values, unknown types; naming the file,
        row and column.
    """
    table = read_table(path)
    image = text_column(table, find_column(table, ("image_id", "image", "photo")))
    point_col = find_column(table, ("point_id", "point", "id", "name"))
    point = text_column(table, point_col)
    col = float_column(table, find_column(table, ("col", "column", "x_px")))
    row = float_column(table, find_column(table, ("row", "y_px")))
    s_col = find_column(table, ("sigma_px", "sigma"), required=False)
    if s_col is None:
        sigma = np.full(len(table), DEFAULT_SIGMA_PX)
    else:
        sigma = float_column(table, s_col, allow_empty=True)
        sigma = np.where(np.isnan(sigma), DEFAULT_SIGMA_PX, sigma)
        bad = np.flatnonzero(sigma <= 0)
        if bad.size:
            raise InputError(
                f"sigma_px must be > 0, got {sigma[bad[0]]}",
                path=table.path,
                row=table.line_numbers[bad[0]],
                column=table.columns[s_col],
            )
    t_col = find_column(table, ("type", "kind", "control_type"))
    kinds = tuple(v.strip().lower() for v in text_column(table, t_col))
    for k, number in zip(kinds, table.line_numbers):
        if k not in OBSERVATION_TYPES:
            raise InputError(
                f"'{k}' is not an observation type ({', '.join(OBSERVATION_TYPES)})",
                path=table.path,
                row=number,
                column=table.columns[t_col],
            )
    g_col = find_column(table, ("target_id", "target", "plane_id", "line_id", "lcp_id"))
    target = text_column(table, g_col)
    # tie rows need their plane id; every other type needs its target too
    return ImageObservations(image, point, np.column_stack([col, row]), sigma, kinds, target)


def write_observations_csv(path: Union[str, Path], obs: ImageObservations) -> None:
    """Write the table atomically (never a half-written file)."""
    rows = (
        (i, p, repr(float(c)), repr(float(r)), repr(float(s)), t, g)
        for i, p, (c, r), s, t, g in zip(
            obs.image_id, obs.point_id, obs.pixels, obs.sigma_px, obs.type, obs.target_id
        )
    )
    write_csv_atomic(path, OBSERVATION_COLUMNS, rows)
