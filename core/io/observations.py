"""Image observations: the CSV table (the in-memory form is :mod:`core.photo.observations`).

One row per measurement of a point in one image (header row; names case-insensitive)::

    image_id,point_id,col,row,sigma_px,type,target_id

image_id
    The image, as in the trajectory table.
point_id
    Name of the measured point. For ``tie`` it names the tie point: every row with the same
    ``point_id`` is the same ground point seen in another image. For ``control`` it is the
    surveyed point's id in the ground (control) points table. For the other types it only
    labels the row (it may repeat across images).
col, row
    Measured pixel position: origin at the top-left corner of the top-left pixel, so the
    centre of the first pixel is (0.5, 0.5); columns grow to the right, rows downwards.
sigma_px
    A-priori standard deviation of col and row, pixels (> 0, at most 100). Empty: 0.5 px.
type
    ``tie``   a roof point measured in two or more images, lying on plane ``target_id``;
    ``line``  a point anywhere on the LiDAR line ``target_id`` (ridge, hip or valley);
    ``lcp``   the LiDAR control point ``target_id`` (three-plane intersection);
    ``paper`` a point on plane ``target_id`` for the single-image model of Pedrosa & dos
              Santos (2020) (its Eqs. 12-17);
    ``check`` the LiDAR control point ``target_id`` used only as a check point (not adjusted);
    ``control`` the surveyed ground point ``point_id`` of the ground points table (its role,
              control or check, comes from that table; ``target_id`` empty), as
              ``locatecontrolpoints`` writes it.
    Optional: without the column every row is ``tie``.
target_id
    Id of the plane, line or LCP in its table (integers in the project's tables). Optional
    (empty) for the bundle adjustment, whose points are named by ``point_id`` alone.
camera
    Optional: the camera (its ``name`` in the camera JSON) of the row's image, for blocks
    flown with several cameras.

A row repeated (same image_id, point_id, type, target_id, col and row) is an error: it would
count twice. Errors name the file, the row (the header is row 1) and the column. The
image-picking dock writes the same table.
"""

from __future__ import annotations

from pathlib import Path
from typing import Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..photo.observations import DEFAULT_SIGMA_PX, OBSERVATION_TYPES, ImageObservations
from .tables import (
    Table,
    choice_column,
    find_column,
    float_column,
    read_table,
    refuse_rows,
    text_column,
    write_csv_atomic,
)

__all__ = [
    "OBSERVATION_COLUMNS",
    "observation_cells",
    "read_observations_csv",
    "write_observations_csv",
]

OBSERVATION_COLUMNS = ("image_id", "point_id", "col", "row", "sigma_px", "type", "target_id")
#: Largest a-priori sigma of an image measurement, pixels: beyond it the row cannot inform the
#: adjustment and is most likely in another unit (micrometres, millimetres).
MAX_SIGMA_PX = 100.0

Array = NDArray[np.float64]


def read_observations_csv(
    path: Union[str, Path], camera: Camera | None = None
) -> ImageObservations:
    """Read the observation table (format in the module docstring).

    With ``camera``, every measured pixel must lie on the image (0 <= col <= width_px,
    0 <= row <= height_px).

    Raises
    ------
    InputError
        Missing columns, non-numeric values, sigma_px not in (0, 100] px, unknown types, a
        duplicate row, a pixel off the camera's image; naming the file, row and column.
    """
    table = read_table(path)
    image = text_column(table, find_column(table, ("image_id", "image", "photo")))
    point_col = find_column(table, ("point_id", "point", "id", "name"))
    point = text_column(table, point_col)
    c_col = find_column(table, ("col", "column", "x_px"))
    r_col = find_column(table, ("row", "y_px"))
    col, row = float_column(table, c_col), float_column(table, r_col)
    s_col = find_column(table, ("sigma_px", "sigma"), required=False)
    if s_col is None:
        sigma = np.full(len(table), DEFAULT_SIGMA_PX)
    else:
        sigma = float_column(table, s_col, allow_empty=True)
        sigma = np.where(np.isnan(sigma), DEFAULT_SIGMA_PX, sigma)
        refuse_rows(
            table,
            (sigma <= 0) | (sigma > MAX_SIGMA_PX),
            s_col,
            lambda k: f"sigma_px must be > 0 and <= {MAX_SIGMA_PX:g} pixels, got {sigma[k]:g}",
        )
    t_col = find_column(table, ("type", "kind", "control_type"), required=False)
    if t_col is None:
        kinds = ("tie",) * len(table)
    else:
        kinds = choice_column(table, t_col, OBSERVATION_TYPES, "an observation type")
    g_col = find_column(
        table, ("target_id", "target", "plane_id", "line_id", "lcp_id"), required=False
    )
    target = ("",) * len(table) if g_col is None else text_column(table, g_col, nonempty=False)
    cam_col = find_column(table, ("camera", "camera_id", "camera_name"), required=False)
    cameras = () if cam_col is None else text_column(table, cam_col)
    # tie rows need their plane id for the boresight calibration, which checks it.
    # A row copied twice would count twice; the same point measured again (another pixel)
    # is a second measurement, as the picking dock records it
    first: dict[tuple[object, ...], int] = {}
    for key, number in zip(zip(image, point, kinds, target, col, row), table.line_numbers):
        if key in first:
            raise InputError(
                f"row {first[key]} again (point '{key[1]}' of image '{key[0]}' at the same "
                "pixel): a duplicate row would count twice; remove one of them",
                path=table.path,
                row=number,
            )
        first[key] = number
    if camera is not None:
        _check_in_image(table, col, c_col, camera.width_px, "width_px", camera.name)
        _check_in_image(table, row, r_col, camera.height_px, "height_px", camera.name)
    return ImageObservations(
        image,
        point,
        np.column_stack([col, row]),
        sigma,
        kinds,
        target,
        table.line_numbers,
        table.path,
        cameras,
    )


def _check_in_image(
    table: Table, values: NDArray[np.float64], index: int, size: int, what: str, camera: str
) -> None:
    """Pixel coordinates ``values`` (column ``index``) within 0 to ``size`` (the camera's
    ``what``, width_px or height_px)."""
    off = (values < 0) | (values > size)
    refuse_rows(
        table,
        off,
        index,
        lambda k: (
            f"{values[k]:g} px is off the image: the camera '{camera}' has {what} {size} "
            f"(pixels from 0 to {size}); {np.count_nonzero(off)} row(s) affected"
        ),
    )


def observation_cells(
    image_id: str, point_id: str, col: float, row: float, sigma_px: float, kind: str, target: str
) -> tuple[str, ...]:
    """The cells of one row as :func:`write_observations_csv` writes them (numbers by
    ``repr``: they read back to the same float).

    >>> observation_cells("img1", "T1", 10.5, 20.25, 0.5, "tie", "7")
    ('img1', 'T1', '10.5', '20.25', '0.5', 'tie', '7')
    """
    return (
        str(image_id),
        str(point_id),
        repr(float(col)),
        repr(float(row)),
        repr(float(sigma_px)),
        str(kind),
        str(target),
    )


def write_observations_csv(path: Union[str, Path], obs: ImageObservations) -> None:
    """Write the table atomically (never a half-written file)."""
    rows = (
        observation_cells(i, p, c, r, s, t, g)
        for i, p, (c, r), s, t, g in zip(
            obs.image_id, obs.point_id, obs.pixels, obs.sigma_px, obs.type, obs.target_id
        )
    )
    write_csv_atomic(path, OBSERVATION_COLUMNS, rows)
