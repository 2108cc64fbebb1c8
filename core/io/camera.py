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
``"sigmas"`` (an object of standard deviations by parameter name, e.g. ``{"focal_mm": 0.002,
"k1": 1e-6}``, written by the bundle adjustment for its estimates) is informative and ignored
on reading.

``"projection"`` (optional, default ``"perspective"``) is the camera's projection:
``"perspective"``, or one of the fisheye projections ``"equidistant"``, ``"equisolid"``,
``"orthographic"``, ``"stereographic"`` (:mod:`core.geometry.projection`), each with the
same lens correction added. Readers refuse a fisheye camera unless the caller states that
it handles one (``projections=``): the algorithms whose kernels are perspective-only thus
name the file instead of treating a fisheye as perspective.

Several cameras (a block flown with more than one) are one file ``{"cameras": [camera, ...]}``
(:func:`read_cameras_json`, :func:`write_cameras_json`); each camera's ``name`` then tells
them apart.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, Union

from ..errors import InputError
from ..geometry.camera import Camera, camera_from_dict
from .atomic import write_text_atomic


def _load(path: Path) -> Any:
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read camera file: {exc}", path=str(path)) from exc
    if not text.strip():
        raise InputError("empty camera file (no JSON object)", path=str(path))

    def no_constants(token: str) -> float:
        raise ValueError(f"{token} is not allowed")

    try:
        return json.loads(text, parse_constant=no_constants)
    except json.JSONDecodeError as exc:
        ends = exc.pos >= len(text.rstrip()) or exc.msg.startswith("Unterminated string")
        cut = " (the file ends inside it: truncated?)" if ends else ""
        raise InputError(
            f"invalid JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}{cut}",
            path=str(path),
        ) from exc
    except ValueError as exc:
        raise InputError(f"invalid JSON: {exc}", path=str(path)) from exc


def _check_projection(cam: Camera, path: Path, projections: Sequence[str]) -> Camera:
    if cam.projection not in projections:
        raise InputError(
            f"camera {cam.name!r} has the {cam.projection} (fisheye) projection; this "
            f"algorithm handles {' and '.join(projections)} cameras only",
            path=str(path),
        )
    return cam


def read_cameras_json(
    path: Union[str, Path], projections: Sequence[str] = ("perspective",)
) -> list[Camera]:
    """Read a file with one camera, or several as ``{"cameras": [...]}`` (unique names).

    ``projections``: the projections the caller handles (others raise :class:`InputError`).
    """
    path = Path(path)
    data = _load(path)
    if isinstance(data, Mapping) and "cameras" in data:
        items = data["cameras"]
        if not isinstance(items, list) or not items:
            raise InputError("key 'cameras': must be a non-empty list", path=str(path))
        cams = [
            camera_from_dict(
                {k: v for k, v in item.items() if k != "sigmas"}
                if isinstance(item, Mapping)
                else item,
                source=str(path),
                default_name=f"{path.stem}_{i + 1}",
            )
            for i, item in enumerate(items)
        ]
        for cam in cams:
            _check_projection(cam, path, projections)
        names = [c.name for c in cams]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise InputError(f"two cameras are named {dup[0]!r}", path=str(path))
        return cams
    return [read_camera_json(path, projections)]


def write_cameras_json(
    path: Union[str, Path],
    cameras: Sequence[Camera],
    sigmas: Sequence[Mapping[str, float]] | None = None,
    extra: Mapping[str, Any] | None = None,
) -> None:
    """Write one camera (an object) or several (``{"cameras": [...]}``), each with its
    ``"sigmas"`` when given, and ``extra`` informative keys (names starting with ``_``)."""
    items = []
    for k, cam in enumerate(cameras):
        d = cam.to_dict()
        if sigmas is not None and sigmas[k]:
            d["sigmas"] = {n: float(v) for n, v in sigmas[k].items() if math.isfinite(v)}
        items.append(d)
    data: dict[str, Any] = items[0] if len(items) == 1 else {"cameras": items}
    if extra:
        data = {**data, **{k if k.startswith("_") else f"_{k}": v for k, v in extra.items()}}
    write_text_atomic(path, json.dumps(data, indent=2, allow_nan=False) + "\n")


def read_camera_json(
    path: Union[str, Path], projections: Sequence[str] = ("perspective",)
) -> Camera:
    """Read a camera JSON file (format in the module docstring).

    ``projections``: the projections the caller handles (others raise :class:`InputError`).

    Raises
    ------
    InputError
        If the file cannot be read, is empty, truncated or not valid JSON, or has a bad or
        missing value; the message names the file and the key (or the line, for invalid
        JSON).
    """
    path = Path(path)
    data = _load(path)
    cam = camera_from_dict(data, source=str(path), default_name=path.stem)
    return _check_projection(cam, path, projections)


def write_camera_json(path: Union[str, Path], camera: Camera) -> None:
    """Write ``camera`` to ``path`` as JSON in millimetres (round-trips exactly), atomically."""
    # json writes floats with repr(), the shortest string that reads back to the same double.
    text = json.dumps(camera.to_dict(), indent=2, allow_nan=False)
    write_text_atomic(path, text + "\n")
