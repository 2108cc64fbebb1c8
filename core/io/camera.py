"""Camera files (JSON).

A camera is stored in millimetres with its pixel size::

    {
      "name": "UltraCam Eagle",
      "focal_mm": 100.5,
      "pixel_size_mm": 0.004,
      "width_px": 26000,
      "height_px": 17000,
      "x0_mm": 0.012,
      "y0_mm": -0.008,
      "distortion": {"model": "brown_conrady",
                     "k1": -5e-05, "k2": 1e-08, "k3": 0.0, "p1": 2e-06, "p2": 0.0}
    }

``name`` defaults to the file's stem; ``x0_mm``/``y0_mm`` default to 0; ``distortion``
defaults to ``{"model": "none"}`` and missing coefficients to 0. A camera may instead be
given in pixels: ``"focal_px"`` replaces ``"focal_mm"`` and ``"ppx_px"``/``"ppy_px"``, the
principal point as a pixel position (col, row) in the convention above (defaults ``W/2``,
``H/2``), replace ``"x0_mm"``/``"y0_mm"``; ``"pixel_size_mm"`` is still required, since
the project works in millimetres. Distortion coefficients are always those of
:mod:`core.geometry.distortion`, defined for millimetre coordinates (not OpenCV's normalised ones).
Keys ``"description"`` and any key starting with ``"_"`` are ignored (comments); any other
unknown key is an error, so that a misspelt key is never silently dropped. Values outside the
physical ranges (a pixel of 0.5 um to 0.5 mm, a focal length of 1 mm to 5 m, at most 200000
pixels a side, the principal point on the image) are refused: they are in another unit.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Union

from ..errors import InputError
from ..geometry.camera import Camera, camera_from_dict
from .atomic import write_text_atomic


def read_camera_json(path: Union[str, Path]) -> Camera:
    """Read a camera JSON file (format in the module docstring).

    Raises
    ------
    InputError
        If the file cannot be read, is not valid JSON, or has a bad or missing value; the
        message names the file and the key (or the line, for invalid JSON).
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read camera file: {exc}", path=str(path)) from exc

    def no_constants(token: str) -> float:
        raise ValueError(f"{token} is not allowed")

    try:
        data = json.loads(text, parse_constant=no_constants)
    except json.JSONDecodeError as exc:
        raise InputError(
            f"invalid JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}", path=str(path)
        ) from exc
    except ValueError as exc:
        raise InputError(f"invalid JSON: {exc}", path=str(path)) from exc
    return camera_from_dict(data, source=str(path), default_name=path.stem)


def write_camera_json(path: Union[str, Path], camera: Camera) -> None:
    """Write ``camera`` to ``path`` as JSON in millimetres (round-trips exactly), atomically."""
    # json writes floats with repr(), the shortest string that reads back to the same double.
    text = json.dumps(camera.to_dict(), indent=2, allow_nan=False)
    write_text_atomic(path, text + "\n")
