"""Space resection in the mapping CRS (:mod:`.resection`): the control sets (points, lines),
the resection run in a local ENU frame and reported in the mapping CRS, and what each image
contributes from the observation table.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.frames import LocalFrame, MappingFrame
from ..geometry.rotations import matrix_to_opk, opk_to_matrix
from .observations import ImageObservations
from .orientation import eo_local_to_map, eo_map_to_local
from .resection import ResectionData, ResectionOptions, SpaceResection, resect

Array = NDArray[np.float64]


@dataclass(frozen=True)
class PointControl:
    """Control points: ids (N,), coordinates (N, 3) and covariances (N, 3, 3) (zero:
    errorless), in one frame."""

    ids: tuple[str, ...]
    xyz: Array
    covariance: Array

    def index(self) -> dict[str, int]:
        return {i: k for k, i in enumerate(self.ids)}


@dataclass(frozen=True)
class LineControl:
    """3D lines: ids (L,), two points each (L, 3) and the covariance (L, 6, 6) of (P1, P2)
    (zero: errorless), in one frame."""

    ids: tuple[str, ...]
    p1: Array
    p2: Array
    covariance: Array

    def index(self) -> dict[str, int]:
        return {i: k for k, i in enumerate(self.ids)}


def line_control_from_lines(lines) -> LineControl:
    """LiDAR lines (:class:`core.lidar.control.ControlLine`: ``X0``, ``u`` and the 6 x 6
    covariance of (X0, u)) as their end points with the propagated covariance of (P1, P2),
    ``P = X0 + t u`` at each end's ``t``.

    >>> from lidarphoto.core.lidar.control import ControlLine
    >>> ln = ControlLine(7, (1, 2), "ridge", np.array([0.0, 0, 5]), np.array([10.0, 0, 5]),
    ...                  np.array([5.0, 0, 5]), np.array([1.0, 0, 0]), np.eye(6) * 1e-4, 90.0)
    >>> lc = line_control_from_lines([ln])
    >>> lc.ids, lc.p1.tolist(), round(float(lc.covariance[0, 1, 1]), 8)
    (('7',), [[0.0, 0.0, 5.0]], 0.0026)
    """
    n = len(lines)
    p1 = np.array([ln.start for ln in lines], dtype=np.float64).reshape(n, 3)
    p2 = np.array([ln.end for ln in lines], dtype=np.float64).reshape(n, 3)
    x0 = np.array([ln.point for ln in lines], dtype=np.float64).reshape(n, 3)
    u = np.array([ln.direction for ln in lines], dtype=np.float64).reshape(n, 3)
    cov = np.array([ln.covariance for ln in lines], dtype=np.float64).reshape(n, 6, 6)
    t1 = np.einsum("li,li->l", p1 - x0, u)
    t2 = np.einsum("li,li->l", p2 - x0, u)
    jac = np.zeros((n, 6, 6))
    eye = np.eye(3)
    jac[:, :3, :3] = eye
    jac[:, 3:, :3] = eye
    jac[:, :3, 3:] = t1[:, None, None] * eye
    jac[:, 3:, 3:] = t2[:, None, None] * eye
    c = jac @ cov @ np.swapaxes(jac, 1, 2)
    return LineControl(tuple(str(ln.id) for ln in lines), p1, p2, 0.5 * (c + np.swapaxes(c, 1, 2)))


# ============================================================================ mapping frame


@dataclass(frozen=True)
class MapResection:
    """A resection run in the local ENU frame and reported in the mapping CRS.

    Attributes
    ----------
    image_id : str
    xyz : ndarray, shape (3,)
        Perspective centre (easting, northing, height), mapping CRS.
    opk : ndarray, shape (3,)
        Omega, phi, kappa relative to the grid frame at the centre, radians (as the EO CSV).
    covariance : ndarray, shape (6, 6)
        A-posteriori covariance of ``(X, Y, Z, omega, phi, kappa)`` in that frame (m, rad).
    result : SpaceResection
        The adjustment, in the local frame.
    data : ResectionData
        Its observations and control, in the local frame.
    local : LocalFrame
    """

    image_id: str
    xyz: Array
    opk: Array
    covariance: Array
    result: SpaceResection
    data: ResectionData
    local: LocalFrame

    @property
    def std(self) -> Array:
        """Standard deviations of ``(X, Y, Z, omega, phi, kappa)``, metres and radians."""
        return np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))

    @property
    def eo_local(self) -> Array:
        return self.result.eo


def _eo_to_map(local: LocalFrame, eo: Array) -> Array:
    m = opk_to_matrix(eo[3], eo[4], eo[5])[None]
    xyz, opk = eo_local_to_map(eo[None, :3], m, local)
    return np.concatenate([xyz[0], opk[0]])


def data_to_local(data: ResectionData, local: LocalFrame) -> ResectionData:
    """The control of ``data`` (mapping CRS) in the ENU frame, covariances propagated."""
    xyz, jx = local.map_to_enu_jacobian(data.xyz)
    p1, j1 = local.map_to_enu_jacobian(data.line_p1)
    p2, j2 = local.map_to_enu_jacobian(data.line_p2)
    jl = np.zeros((data.n_lines, 6, 6))
    jl[:, :3, :3], jl[:, 3:, 3:] = j1, j2
    return replace(
        data,
        xyz=xyz,
        xyz_cov=jx @ data.xyz_cov @ np.swapaxes(jx, 1, 2),
        line_p1=p1,
        line_p2=p2,
        line_cov=jl @ data.line_cov @ np.swapaxes(jl, 1, 2),
    )


def resect_in_map(
    image_id: str,
    data: ResectionData,
    camera: Camera,
    mapping: MappingFrame,
    options: ResectionOptions | None = None,
    eo0: ArrayLike | None = None,
    local: LocalFrame | None = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> MapResection:
    """:func:`resect` with the control in a mapping CRS, run in a local ENU frame.

    Parameters
    ----------
    image_id : str
    data : ResectionData
        Control coordinates in the mapping CRS (easting, northing, height, metres).
    mapping : MappingFrame
    eo0 : (6,) array_like, optional
        Start ``(X, Y, Z, omega, phi, kappa)`` in the mapping CRS, angles relative to the grid
        frame (radians), as the EO CSV.
    local : LocalFrame, optional
        The adjustment frame; by default tangent at the centroid of the control.

    Returns
    -------
    MapResection
    """
    if local is None:
        everything = np.vstack([data.xyz, data.line_p1, data.line_p2])
        if not len(everything):
            raise InputError(f"image {image_id}: no control points or lines")
        local = LocalFrame.at_map_point(mapping, everything.mean(axis=0))
    d_local = data_to_local(data, local)
    start = None
    if eo0 is not None:
        e = np.asarray(eo0, dtype=np.float64).reshape(6)
        centre, m = eo_map_to_local(e[None, :3], e[None, 3:], local)
        start = np.concatenate([centre[0], matrix_to_opk(m[0])])
    res = resect(d_local, camera, options, start, progress, should_stop)
    out = _eo_to_map(local, res.eo)
    # the covariance in the mapping frame through the Jacobian of the conversion
    jac = np.empty((6, 6))
    steps = (1e-3, 1e-3, 1e-3, 1e-7, 1e-7, 1e-7)
    for k, h in enumerate(steps):
        ep, em = res.eo.copy(), res.eo.copy()
        ep[k] += h
        em[k] -= h
        diff = _eo_to_map(local, ep) - _eo_to_map(local, em)
        diff[3:] = (diff[3:] + np.pi) % (2 * np.pi) - np.pi
        jac[:, k] = diff / (2 * h)
    cov = jac @ res.covariance @ jac.T
    return MapResection(image_id, out[:3], out[3:], 0.5 * (cov + cov.T), res, d_local, local)


# ============================================================================ from observations


@dataclass(frozen=True)
class ImageInput:
    """What one image contributes to its resection, taken from the observation table.

    Attributes
    ----------
    image_id : str
    data : ResectionData
        Control points and lines of the image (the control's frame).
    point_rows, line_rows : tuple
        Rows of the observation table of each control point (int) and of each line (tuple of
        ints, the points measured on it in file order).
    check_rows : tuple of int
        Rows of type ``check``; ``check_xyz`` (C, 3) their control points.
    ignored : int
        Rows that are neither control nor check (e.g. tie points without object coordinates).
    """

    image_id: str
    data: ResectionData
    point_rows: tuple[int, ...]
    line_rows: tuple[tuple[int, ...], ...]
    check_rows: tuple[int, ...]
    check_xyz: Array
    ignored: int


def image_inputs(
    observations: ImageObservations,
    points: PointControl | None,
    lines: LineControl | None,
    image_ids: Sequence[str] | None = None,
) -> list[ImageInput]:
    """Match the observation rows of each image to the control.

    Rules: rows of type ``line`` with the same image and ``target_id`` are one image line
    (two or more points in file order) matched to the 3D line of that id; rows of type
    ``lcp`` are control points and ``check`` rows check points, both matched by ``target_id``;
    rows of other types (``tie``, ``paper``) are control points when their ``point_id`` is a
    control point id and are ignored otherwise. Without control lines (points) the line
    (lcp, check) rows are ignored.

    Raises
    ------
    InputError
        An image asked for that has no observation, a line or control point id that is not in
        the control, an image line with a single point.
    """
    by_image: dict[str, list[int]] = {}
    for k, img in enumerate(observations.image_id):
        by_image.setdefault(img, []).append(k)
    wanted = list(by_image) if not image_ids else list(image_ids)
    missing = [i for i in wanted if i not in by_image]
    if missing:
        raise InputError(f"no observations of image(s) {', '.join(missing[:10])}")
    p_index = points.index() if points is not None else {}
    l_index = lines.index() if lines is not None else {}
    out = []
    for img in wanted:
        # observation rows and control indices of the points used, and of the check points
        p_rows: list[int] = []
        p_ctrl: list[int] = []
        c_rows: list[int] = []
        c_ctrl: list[int] = []
        groups: dict[str, list[int]] = {}
        ignored = 0
        for k in by_image[img]:
            kind, target, pid = (
                observations.type[k],
                observations.target_id[k],
                observations.point_id[k],
            )
            if kind == "line":
                if lines is None:
                    ignored += 1
                    continue
                if target not in l_index:
                    raise InputError(
                        f"image {img}: line '{target}' (point {pid}) is not in the "
                        f"control lines ({len(l_index)} ids)"
                    )
                groups.setdefault(target, []).append(k)
            elif kind in ("lcp", "check"):
                if points is None:
                    ignored += 1
                    continue
                if target not in p_index:
                    raise InputError(
                        f"image {img}: control point '{target}' ({kind} row, point "
                        f"{pid}) is not in the control points"
                    )
                (c_rows if kind == "check" else p_rows).append(k)
                (c_ctrl if kind == "check" else p_ctrl).append(p_index[target])
            elif pid in p_index:
                p_rows.append(k)
                p_ctrl.append(p_index[pid])
            else:
                ignored += 1
        for target, rows in groups.items():
            if len(rows) < 2:
                raise InputError(
                    f"image {img}: line '{target}' has a single point "
                    f"({observations.point_id[rows[0]]}): measure two or more points on it "
                    "(its two ends)"
                )
        lids = list(groups)
        li = [l_index[t] for t in lids]
        pc = np.array(p_ctrl, dtype=np.int64)
        try:
            data = ResectionData(
                point_ids=tuple(observations.point_id[k] for k in p_rows),
                pixels=observations.pixels[p_rows].reshape(-1, 2),
                sigma_px=observations.sigma_px[p_rows],
                xyz=points.xyz[pc] if points is not None else np.empty((0, 3)),
                xyz_cov=points.covariance[pc] if points is not None else np.empty((0, 3, 3)),
                line_ids=tuple(lids),
                line_pixels=tuple(observations.pixels[groups[t]] for t in lids),
                line_sigma_px=tuple(observations.sigma_px[groups[t]] for t in lids),
                line_p1=lines.p1[li] if lines is not None else np.empty((0, 3)),
                line_p2=lines.p2[li] if lines is not None else np.empty((0, 3)),
                line_cov=lines.covariance[li] if lines is not None else np.empty((0, 6, 6)),
            )
        except InputError as exc:  # the checks of ResectionData, with the image named
            raise InputError(f"image {img}: {exc}") from None
        cxyz = (
            points.xyz[np.array(c_ctrl, dtype=np.int64)]
            if points is not None
            else (np.empty((0, 3)))
        )
        out.append(
            ImageInput(
                img,
                data,
                tuple(p_rows),
                tuple(tuple(groups[t]) for t in lids),
                tuple(c_rows),
                cxyz.reshape(-1, 3),
                ignored,
            )
        )
    return out


def control_frame(inputs: Sequence[ImageInput], frame: MappingFrame) -> LocalFrame:
    """The ENU frame the images of ``inputs`` are resected in: tangent at the mean of all
    their control (points and line end points, mapping CRS), one frame for the block.

    Raises
    ------
    InputError
        No observation matched the control.
    """
    everything = [d.data for d in inputs]
    ctrl = np.vstack([np.vstack([d.xyz, d.line_p1, d.line_p2]) for d in everything])
    if not len(ctrl):
        raise InputError("no observation matches the control: check the point and line ids")
    return LocalFrame.at_map_point(frame, ctrl.mean(axis=0))
