"""The block-level geometry of orthorectification (:mod:`.orthophoto` makes one image): the
projectors of all images in one ENU frame, the surface height under each footprint, how much of
an image's border falls beyond the surface, and the cell size of the block (the rule of
``OrthoOptions.gsd``: given, or the images' nadir GSD)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.frames import LocalFrame, MappingFrame
from ..geometry.raycast import DsmTracer
from ..geometry.surface import Dsm
from .ortho_options import OrthoOptions
from .orthophoto import OrthoProjector, _lens_lattice, auto_gsd


def block_projectors(
    camera: Camera,
    poses: Mapping[str, tuple[ArrayLike, ArrayLike]],
    dsm: Dsm,
    surface: Dsm | DsmTracer,
    mapping,
) -> dict[str, OrthoProjector]:
    """One :class:`OrthoProjector` per image of ``poses`` (image id -> (centre, omega-phi-kappa),
    mapping CRS, radians), all in one ENU frame (at the DSM's centre, its lowest height) and
    sharing one lens lattice; ``surface`` is the DSM or its tracer (true orthophotos)."""
    lens = _lens_lattice(camera)
    g = dsm.grid
    centre = [g.x0 + g.cols * g.cell / 2, g.y_top - g.rows * g.cell / 2, dsm.z_range[0]]
    local = LocalFrame.at_map_point(MappingFrame(mapping), centre)
    return {
        name: OrthoProjector.build(camera, xyz, opk, surface, mapping, local=local, lens=lens)
        for name, (xyz, opk) in poses.items()
    }


def median_height(dsm: Dsm, box: Sequence[float] | None) -> float:
    """Median surface height (CRS unit) inside the box (xmin, ymin, xmax, ymax), from a
    subsample of at most about 250,000 of its cells; NaN without a box or a height there."""
    if box is None:
        return math.nan
    g = dsm.grid
    c0 = max(int((box[0] - g.x0) / g.cell), 0)
    c1 = min(math.ceil((box[2] - g.x0) / g.cell), g.cols)
    r0 = max(int((g.y_top - box[3]) / g.cell), 0)
    r1 = min(math.ceil((g.y_top - box[1]) / g.cell), g.rows)
    sub = dsm.heights[r0:r1, c0:c1]
    step = max(1, int(math.sqrt(sub.size / 250000)))
    vals = sub[::step, ::step]
    vals = vals[np.isfinite(vals)]
    return float(np.median(vals)) if vals.size else math.nan


def share_beyond_dsm(proj: OrthoProjector, ground_z: float) -> float:
    """Share (0-1) of the image's border whose ground, at height ``ground_z``, lies beyond the
    DSM's cell centres (33 points a side)."""
    cam = proj.camera
    border = cam.border_pixels(32)
    xy = proj.ground_points(border, ground_z)
    g = proj.dsm.grid
    xc, yc = proj.dsm.centre_origin
    inside = (
        (xy[:, 0] >= xc)
        & (xy[:, 0] <= xc + (g.cols - 1) * g.cell)
        & (xy[:, 1] <= yc)
        & (xy[:, 1] >= yc - (g.rows - 1) * g.cell)
    )
    return float(1.0 - inside.mean())


def block_gsd(
    options: OrthoOptions,
    camera: Camera,
    projectors: Mapping[str, OrthoProjector],
    ground_z: Mapping[str, float],
    *,
    path: str | None = None,
) -> float:
    """The cell size of the block's orthophotos (CRS unit): ``options.gsd`` when it is given
    (> 0), else the median over the images that see the surface of their nadir GSD at the
    median height under their footprint (:func:`~.orthophoto.auto_gsd`, 2 significant digits).
    ``path`` (the surface's file) names the error when no image sees the surface.

    >>> from types import SimpleNamespace
    >>> cam = Camera("c", 35.0, 0.0045, 6000, 4000)
    >>> projs = {"a": SimpleNamespace(xyz=(0.0, 0.0, 130.0))}
    >>> block_gsd(OrthoOptions(), cam, projs, {"a": 0.0})
    0.017
    >>> block_gsd(OrthoOptions(gsd=0.1), cam, projs, {})
    0.1
    """
    if options.gsd > 0:
        return float(options.gsd)
    gsds = [
        auto_gsd(camera, p.xyz[2], ground_z[k])
        for k, p in projectors.items()
        if np.isfinite(ground_z[k])
    ]
    if not gsds:
        raise InputError("no image sees the DSM", path=path)
    return float(np.median(gsds))
