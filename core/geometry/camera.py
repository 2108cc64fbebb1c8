"""Frame cameras: interior orientation, pixel <-> image coordinates.

Conventions (docs/conventions.md, "Images")
-------------------------------------------
- **Pixels** ``(col, row)``, float: the origin is the top-left *corner* of the top-left
  pixel, columns grow to the right and rows downwards, so the centre of the first pixel is
  ``(0.5, 0.5)`` and the image spans ``[0, W] x [0, H]`` (as in GDAL).
- **Image coordinates** in millimetres, relative to the image centre, x right and y up::

      x = (col - W/2) * pixel_size_mm
      y = (H/2 - row) * pixel_size_mm

  The principal point ``(x0_mm, y0_mm)`` is given in this system.
- **Camera frame**: x right, y up, z towards the viewer; the camera looks along -z. A
  measured image point ``(x, y)`` corresponds to the ray ``(x - x0 + dx, y - y0 + dy, -f)``
  where ``d`` is the lens correction of :mod:`core.geometry.distortion` evaluated at the measured,
  centred coordinate. "Ideal" coordinates below are ``(x - x0 + dx, y - y0 + dy)``.

Camera files (JSON) are read and written by :mod:`core.io.camera`, which documents the
format; :func:`camera_from_dict` checks their content.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Dict, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from . import ap_models as _ap_models  # noqa: F401  (registers the AP families' lens models)
from . import forward_lens as _forward_lens  # noqa: F401  (registers the forward models)
from .distortion import (
    DEFAULT_MAX_ITER,
    DistortionModel,
    NoDistortion,
    as_points,
    distortion_from_dict,
)
from .projection import PROJECTIONS, ray_from_ideal

Array = NDArray[np.float64]

#: Tolerance of the ideal -> measured inversion, in pixels (docs/conventions.md, "Images").
DEFAULT_TOL_PX = 1e-6

__all__ = [
    "DEFAULT_TOL_PX",
    "Camera",
    "camera_from_dict",
]


def _check_finite(value: Any, what: str) -> float:
    if isinstance(value, bool):
        raise InputError(f"{what} must be a number, got {value!r}")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a number, got {value!r}") from None
    if not math.isfinite(number):
        raise InputError(f"{what} must be finite, got {value!r}")
    return number


def _check_positive(value: Any, what: str) -> float:
    number = _check_finite(value, what)
    if number <= 0.0:
        raise InputError(f"{what} must be a positive finite number, got {value!r}")
    return number


def _check_size(value: Any, what: str) -> int:
    number = _check_positive(value, what)
    if number != int(number):
        raise InputError(f"{what} must be a whole number of pixels, got {value!r}")
    return int(number)


@dataclass(frozen=True)
class Camera:
    """Interior orientation of a frame camera (immutable, validated).

    Parameters
    ----------
    name : str
        Identifier of the camera.
    focal_mm : float
        Principal distance f, mm, > 0.
    pixel_size_mm : float
        Side of a (square) pixel, mm, > 0.
    width_px, height_px : int
        Image size W, H in pixels, > 0.
    x0_mm, y0_mm : float
        Principal point in image coordinates (x right, y up, from the image centre), mm.
    distortion : DistortionModel
        Lens correction (measured -> ideal), :class:`~core.geometry.distortion.NoDistortion` by
        default.
    projection : str
        ``"perspective"`` (default: the central projection ``r = f tan(theta)``) or a fisheye
        projection of :mod:`core.geometry.projection` (``"equidistant"``, ``"equisolid"``,
        ``"orthographic"``, ``"stereographic"``); the lens correction is added to any of them.

    Raises
    ------
    InputError
        Naming the field, for a non-positive or non-finite focal length or pixel size, a
        non-positive or fractional image size, a non-finite principal point or a
        distortion that is not a :class:`~core.geometry.distortion.DistortionModel`.

    Examples
    --------
    >>> cam = Camera("c", focal_mm=100.0, pixel_size_mm=0.004, width_px=26000, height_px=17000)
    >>> cam.pixel_to_image([[0.5, 0.5]]).round(6).tolist()
    [[-51.998, 33.998]]
    """

    name: str
    focal_mm: float
    pixel_size_mm: float
    width_px: int
    height_px: int
    x0_mm: float = 0.0
    y0_mm: float = 0.0
    distortion: DistortionModel = field(default_factory=NoDistortion)
    projection: str = "perspective"

    def __post_init__(self) -> None:
        """Validate and normalise the fields (raises :class:`InputError` naming the field)."""
        if not isinstance(self.name, str):
            raise InputError(f"camera name must be a string, got {self.name!r}")
        who = f"camera {self.name!r}: "
        # object.__setattr__ because the dataclass is frozen; values are normalised to
        # plain float/int so that equality and JSON output do not depend on the input type.
        set_ = object.__setattr__
        set_(self, "focal_mm", _check_positive(self.focal_mm, who + "focal_mm"))
        set_(self, "pixel_size_mm", _check_positive(self.pixel_size_mm, who + "pixel_size_mm"))
        set_(self, "width_px", _check_size(self.width_px, who + "width_px"))
        set_(self, "height_px", _check_size(self.height_px, who + "height_px"))
        set_(self, "x0_mm", _check_finite(self.x0_mm, who + "x0_mm"))
        set_(self, "y0_mm", _check_finite(self.y0_mm, who + "y0_mm"))
        if self.projection not in PROJECTIONS:
            raise InputError(
                who + f"projection must be one of {', '.join(PROJECTIONS)}, got {self.projection!r}"
            )
        if not isinstance(self.distortion, DistortionModel):
            raise InputError(
                who + f"distortion must be a DistortionModel, got {type(self.distortion).__name__}"
            )

    # ------------------------------------------------------------------ derived values
    @property
    def is_perspective(self) -> bool:
        """True for the central perspective projection (the default), False for a fisheye."""
        return self.projection == "perspective"

    def require_perspective(self, who: str, path: str | None = None) -> None:
        """Raise :class:`InputError` naming ``who`` (and ``path``) for a fisheye camera.

        For the algorithms whose kernels implement the perspective projection only: they must
        refuse a fisheye camera rather than treat it as a perspective one.
        """
        if not self.is_perspective:
            raise InputError(
                f"camera {self.name!r} has the {self.projection} (fisheye) projection; "
                f"{who} handles perspective cameras only",
                path=path,
            )

    def ray_from_ideal(self, xy_ideal: ArrayLike) -> Array:
        """Camera-frame rays (N, 3) of ideal centred coordinates (N, 2) mm (see
        :func:`core.geometry.projection.ray_from_ideal`; ``(x, y, -f)`` for perspective)."""
        return ray_from_ideal(xy_ideal, self.focal_mm, self.projection)

    @property
    def focal_px(self) -> float:
        """Principal distance in pixels, ``focal_mm / pixel_size_mm``."""
        return self.focal_mm / self.pixel_size_mm

    @property
    def principal_point_px(self) -> Tuple[float, float]:
        """Principal point as a pixel position (col, row) (origin: top-left corner)."""
        return (
            self.x0_mm / self.pixel_size_mm + 0.5 * self.width_px,
            0.5 * self.height_px - self.y0_mm / self.pixel_size_mm,
        )

    @property
    def interior_names(self) -> Tuple[str, ...]:
        """Names of :attr:`interior_params`: ``("focal_mm", "x0_mm", "y0_mm", *lens names)``."""
        return ("focal_mm", "x0_mm", "y0_mm", *self.distortion.param_names)

    @property
    def interior_params(self) -> Array:
        """Interior orientation vector (3 + P,): f, x0, y0 (mm), then the lens coefficients."""
        return np.concatenate(
            [[self.focal_mm, self.x0_mm, self.y0_mm], self.distortion.params]
        ).astype(np.float64)

    def with_interior(self, params: ArrayLike) -> Camera:
        """Copy with a new interior orientation vector (3 + P,), in :attr:`interior_names` order."""
        p = np.asarray(params, dtype=np.float64).reshape(-1)
        if p.shape[0] != 3 + self.distortion.n_params:
            raise ValueError(
                f"expected {3 + self.distortion.n_params} interior parameters, got {p.shape[0]}"
            )
        return dataclasses.replace(
            self,
            focal_mm=float(p[0]),
            x0_mm=float(p[1]),
            y0_mm=float(p[2]),
            distortion=self.distortion.with_params(p[3:]),
        )

    # ------------------------------------------------------------------ pixel <-> mm
    def pixel_to_image(self, cols_rows: ArrayLike) -> Array:
        """Pixel positions (N, 2) (col, row) -> image coordinates (N, 2) (x, y) in mm.

        Not centred on the principal point and not corrected for distortion.
        """
        px = as_points(cols_rows, 2, "cols_rows")
        ps = self.pixel_size_mm
        out = np.empty_like(px)
        out[:, 0] = (px[:, 0] - 0.5 * self.width_px) * ps
        out[:, 1] = (0.5 * self.height_px - px[:, 1]) * ps
        return out

    def image_to_pixel(self, xy_mm: ArrayLike) -> Array:
        """Image coordinates (N, 2) (x, y) in mm -> pixel positions (N, 2) (col, row)."""
        xy = as_points(xy_mm, 2, "xy_mm")
        ps = self.pixel_size_mm
        out = np.empty_like(xy)
        out[:, 0] = xy[:, 0] / ps + 0.5 * self.width_px
        out[:, 1] = 0.5 * self.height_px - xy[:, 1] / ps
        return out

    def ideal_from_pixel(self, cols_rows: ArrayLike) -> Array:
        """Measured pixel positions (N, 2) -> ideal, centred image coordinates (N, 2) in mm.

        ``(x - x0 + dx, y - y0 + dy)`` with the correction evaluated at the measured point:
        the first two components of the camera-frame ray (the third is ``-focal_mm``).
        """
        centred = self.pixel_to_image(cols_rows) - np.array([self.x0_mm, self.y0_mm])
        return self.distortion.undistort(centred)

    def measured_from_ideal(
        self,
        xy_ideal: ArrayLike,
        *,
        tol_px: float = DEFAULT_TOL_PX,
        max_iter: int = DEFAULT_MAX_ITER,
    ) -> Tuple[Array, NDArray[np.bool_]]:
        """Ideal centred coordinates (N, 2) mm -> measured centred coordinates (N, 2) mm.

        Inverts the lens correction by Newton's method to ``tol_px`` pixels.

        Returns
        -------
        measured : (N, 2) ndarray
            ``(x - x0, y - y0)`` in mm; NaN where the inversion failed.
        converged : (N,) ndarray of bool
            See :meth:`core.geometry.distortion.DistortionModel.distort_with_status`.
        """
        return self.distortion.distort_with_status(
            xy_ideal, tol_mm=tol_px * self.pixel_size_mm, max_iter=max_iter
        )

    def pixel_from_ideal_with_status(
        self,
        xy_ideal: ArrayLike,
        *,
        tol_px: float = DEFAULT_TOL_PX,
        max_iter: int = DEFAULT_MAX_ITER,
    ) -> Tuple[Array, NDArray[np.bool_]]:
        """Ideal centred coordinates (N, 2) mm -> measured pixels (N, 2), and a converged mask (N,).

        Rows where the lens inversion failed are NaN.
        """
        m, ok = self.measured_from_ideal(xy_ideal, tol_px=tol_px, max_iter=max_iter)
        return self.image_to_pixel(m + np.array([self.x0_mm, self.y0_mm])), ok

    def pixel_from_ideal(
        self,
        xy_ideal: ArrayLike,
        *,
        tol_px: float = DEFAULT_TOL_PX,
        max_iter: int = DEFAULT_MAX_ITER,
    ) -> Array:
        """Ideal centred coordinates (N, 2) mm -> measured pixel positions (N, 2).

        Raises
        ------
        core.geometry.distortion.DistortionInversionError
            If the lens inversion fails for any point (use
            :meth:`pixel_from_ideal_with_status` to get NaN rows and a mask instead).
        """
        m = self.distortion.distort(xy_ideal, tol_mm=tol_px * self.pixel_size_mm, max_iter=max_iter)
        return self.image_to_pixel(m + np.array([self.x0_mm, self.y0_mm]))

    def in_frame(self, cols_rows: ArrayLike, margin_px: float = 0.0) -> NDArray[np.bool_]:
        """(N,) mask of the pixel positions inside the image, shrunk by ``margin_px``."""
        px = as_points(cols_rows, 2, "cols_rows")
        with np.errstate(invalid="ignore"):
            return (
                (px[:, 0] >= margin_px)
                & (px[:, 0] <= self.width_px - margin_px)
                & (px[:, 1] >= margin_px)
                & (px[:, 1] <= self.height_px - margin_px)
            )

    def border_pixels(self, samples: int) -> Array:
        """(4 (samples + 1), 2) pixel positions (col, row) along the image's edges: top,
        bottom, left and right, ``samples + 1`` evenly spaced from corner to corner on each.

        >>> cam = Camera("c", focal_mm=10.0, pixel_size_mm=0.01, width_px=4, height_px=2)
        >>> cam.border_pixels(1)[:4]
        array([[0., 0.],
               [4., 0.],
               [0., 2.],
               [4., 2.]])
        """
        k = np.linspace(0.0, 1.0, samples + 1)
        w, h = self.width_px, self.height_px
        return np.vstack(
            [
                np.column_stack([k * w, np.zeros_like(k)]),
                np.column_stack([k * w, np.full_like(k, h)]),
                np.column_stack([np.zeros_like(k), k * h]),
                np.column_stack([np.full_like(k, w), k * h]),
            ]
        )

    # ------------------------------------------------------------------ files
    def to_dict(self) -> Dict[str, Any]:
        """Return the camera as a JSON-ready dict in millimetres (the format of this module).

        ``"projection"`` is written only for a fisheye camera (perspective is the default).
        """
        out: Dict[str, Any] = {
            "name": self.name,
            "focal_mm": self.focal_mm,
            "pixel_size_mm": self.pixel_size_mm,
            "width_px": self.width_px,
            "height_px": self.height_px,
            "x0_mm": self.x0_mm,
            "y0_mm": self.y0_mm,
            "distortion": self.distortion.to_dict(),
        }
        if not self.is_perspective:
            out["projection"] = self.projection
        return out


#: Physical ranges of a camera file's values: a pixel of 0.5 um to 0.5 mm (scanned film), a
#: focal length of 1 mm to 5 m, at most 200000 pixels a side.
PIXEL_SIZE_RANGE_MM = (0.0005, 0.5)
FOCAL_RANGE_MM = (1.0, 5000.0)
MAX_IMAGE_SIDE_PX = 200_000
_MM_KEYS = ("focal_mm", "x0_mm", "y0_mm")
_PX_KEYS = ("focal_px", "ppx_px", "ppy_px")
_KNOWN_KEYS = {
    "name",
    "pixel_size_mm",
    "width_px",
    "height_px",
    "distortion",
    "sigmas",
    "projection",
}
_KNOWN_KEYS.update(_MM_KEYS, _PX_KEYS)


def camera_from_dict(data: Any, source: str | None = None, default_name: str = "camera") -> Camera:
    """Build a :class:`Camera` from a dict in the JSON format of this module.

    Parameters
    ----------
    data : mapping
        Camera in millimetres or in pixels (see the module docstring).
    source : str, optional
        File the dict came from, named in every error.
    default_name : str
        Name used when ``data`` has no ``"name"``.

    Raises
    ------
    InputError
        For every missing, unknown, ill-typed or out-of-range key, naming ``source`` and the
        key.

    >>> camera_from_dict({"focal_px": 25000, "pixel_size_mm": 0.004, "width_px": 26000,
    ...                   "height_px": 17000, "ppx_px": 13010, "ppy_px": 8500}).x0_mm
    0.04
    """
    if not isinstance(data, Mapping):
        raise InputError(f"a camera must be a JSON object, got {type(data).__name__}", path=source)

    def fail(key: str, message: str) -> InputError:
        return InputError(f"key '{key}': {message}", path=source)

    for key in data:
        if key not in _KNOWN_KEYS and key != "description" and not str(key).startswith("_"):
            raise fail(key, f"unknown key (expected some of {sorted(_KNOWN_KEYS)})")

    def number(key: str, positive: bool) -> float:
        value = data[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise fail(key, f"must be a number, got {value!r}")
        if not math.isfinite(value):
            raise fail(key, f"must be finite, got {value!r}")
        if positive and not value > 0:
            raise fail(key, f"must be positive, got {value!r}")
        return float(value)

    def required(key: str, positive: bool) -> float:
        if key not in data:
            raise fail(key, "is missing")
        return number(key, positive)

    def size(key: str) -> int:
        value = required(key, positive=True)
        if value != int(value):
            raise fail(key, f"must be a whole number of pixels, got {data[key]!r}")
        return int(value)

    name = data.get("name", default_name)
    if not isinstance(name, str):
        raise fail("name", f"must be a string, got {name!r}")
    pixel_size = required("pixel_size_mm", positive=True)
    width, height = size("width_px"), size("height_px")

    for mm_key, px_key in zip(_MM_KEYS, _PX_KEYS):
        if mm_key in data and px_key in data:
            raise fail(px_key, f"give either '{mm_key}' or '{px_key}', not both")
    if "focal_px" in data:
        focal = required("focal_px", positive=True) * pixel_size
    elif "focal_mm" in data:
        focal = required("focal_mm", positive=True)
    else:
        raise fail("focal_mm", "is missing (give 'focal_mm', or 'focal_px' for pixels)")
    if "x0_mm" in data:
        x0 = number("x0_mm", positive=False)
    elif "ppx_px" in data:
        x0 = (number("ppx_px", positive=False) - 0.5 * width) * pixel_size
    else:
        x0 = 0.0
    if "y0_mm" in data:
        y0 = number("y0_mm", positive=False)
    elif "ppy_px" in data:
        y0 = (0.5 * height - number("ppy_px", positive=False)) * pixel_size
    else:
        y0 = 0.0
    # physical ranges: outside them the value is in another unit (um for mm, px for mm)
    for key, value, lo, hi, unit in (
        ("pixel_size_mm", pixel_size, *PIXEL_SIZE_RANGE_MM, "mm"),
        ("focal_mm", focal, *FOCAL_RANGE_MM, "mm"),
        ("width_px", width, 1, MAX_IMAGE_SIDE_PX, "px"),
        ("height_px", height, 1, MAX_IMAGE_SIDE_PX, "px"),
    ):
        if not lo <= value <= hi:
            shown = "focal_px" if key == "focal_mm" and "focal_px" in data else key
            raise fail(
                shown,
                f"{value:g} {unit} is outside the physical range {lo:g} to {hi:g} "
                f"{unit} (a value in another unit?)",
            )
    for key, value, half in (("x0_mm", x0, 0.5 * width), ("y0_mm", y0, 0.5 * height)):
        if abs(value) > half * pixel_size:
            shown = key if key in data else ("ppx_px" if key == "x0_mm" else "ppy_px")
            raise fail(
                shown,
                f"the principal point ({value:g} mm from the image centre) lies "
                f"outside the image ({half * pixel_size:g} mm to its edge)",
            )
    distortion = distortion_from_dict(data.get("distortion", {}), source, "distortion")
    projection = data.get("projection", "perspective")
    if projection not in PROJECTIONS:
        raise fail(
            "projection", f"unknown projection {projection!r} (known: {', '.join(PROJECTIONS)})"
        )
    return Camera(name, focal, pixel_size, width, height, x0, y0, distortion, projection)
