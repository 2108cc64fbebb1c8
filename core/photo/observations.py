"""Image observations: measurements of points in images (col, row in pixels) and what they
are measurements of (tie points on roof planes, points on LiDAR lines, LiDAR control points,
surveyed ground control points).

The types, the pixel convention and the CSV form are described in
:mod:`core.io.observations`.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError

Array = NDArray[np.float64]

OBSERVATION_TYPES = ("tie", "line", "lcp", "paper", "check", "control")

DEFAULT_SIGMA_PX = 0.5


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
    rows : tuple of int, shape (N,) or ()
        Row of each measurement in its file (header = row 1), for error messages.
    source : str
        The file they were read from ("" when made in memory).
    camera : tuple of str, shape (N,) or ()
        Camera of each measurement's image, when the table names it.
    """

    image_id: tuple[str, ...]
    point_id: tuple[str, ...]
    pixels: Array
    sigma_px: Array
    type: tuple[str, ...]
    target_id: tuple[str, ...]
    rows: tuple[int, ...] = ()
    source: str = ""
    camera: tuple[str, ...] = ()

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
        for name in ("rows", "camera"):
            value = tuple(getattr(self, name))
            if value and len(value) != n:
                raise InputError(f"image observations: {name} must have one entry per row")
            object.__setattr__(self, name, value)

    def where(self, i: int) -> dict:
        """``path``/``row`` keywords of :class:`InputError` for measurement ``i``."""
        return {"path": self.source or None, "row": self.rows[i] if self.rows else None}

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

    def require_control_known(self, known: Collection[str], table: str) -> None:
        """Raise :class:`InputError` naming the first ``control`` row whose point_id is not in
        ``known`` (``table``: how the message names the ground-point table). A control row
        measures a surveyed point: it never becomes a free tie point silently.

        >>> o = ImageObservations(("a",), ("P9",), [[1.0, 2.0]], 0.5, ("control",), ("",))
        >>> try:
        ...     o.require_control_known({"P1"}, "CONTROL_POINTS")
        ... except InputError as exc:
        ...     print(exc)
        row of type control names point 'P9', which is not in CONTROL_POINTS
        """
        for k in np.flatnonzero(self.mask("control")):
            if self.point_id[k] not in known:
                raise InputError(
                    f"row of type control names point '{self.point_id[k]}', which is not in "
                    f"{table}",
                    **self.where(int(k)),
                )

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
            tuple(self.rows[i] for i in idx) if self.rows else (),
            self.source,
            tuple(self.camera[i] for i in idx) if self.camera else (),
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
