"""The picking dock's ground geometry with fisheye cameras (Qt-free parts): the image's
footprint (core.photo.picking.PickingScene.footprint) and the monoplot of a clicked pixel
(core.photo.monoplot.monoplot, what plugin/monoplot_tool.py calls), against truth.

Footprint: a fisheye of each projection 40 m over the ground, tilted 12 degrees. A lens whose
frame lies inside its field (f 3 mm, 2000 x 1500 px of 2 um: 48-56 degrees off the axis in
the corners): every vertex on the level surface (1e-6 m) and projected back onto its border
pixel within 0.01 px. A lens wider than the ground it can see (f 2 mm, 3 um: 86-139 degrees
in the corners, beyond the orthographic field): a vertex whose ray does not reach the ground
within FOOTPRINT_RANGE flying heights (or has none: beyond the orthographic field) lies at that
range (1e-3 relative: the range is taken on the tangent plane, the vertex on the level
surface) or at the edge of the field, and projects back inside the frame on the line from the
principal point to its border pixel (0.01 px).

Monoplot: pixels of true ground points (the forward model, rigorous ENU collinearity with the
projection and the lens) on a flat DSM and on a DSM of a tilted plane (1:4 and 1:8 slopes,
heights exact in float32, so that the bilinear surface is the plane): back within 1e-6 m.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.distortion import distortion_from_dict
from lidarphoto.core.geometry.grid import Grid
from lidarphoto.core.geometry.projection import FISHEYE_PROJECTIONS, theta_from_radius
from lidarphoto.core.geometry.surface import Dsm
from lidarphoto.core.photo.monoplot import monoplot
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.photo.orientation import ExteriorOrientationTable
from lidarphoto.core.photo.picking import FOOTPRINT_BORDER_POINTS, FOOTPRINT_RANGE, PickingScene
from lidarphoto.core.photo.tie_pairs import _border

CRS = "EPSG:28992"
CENTRE = np.array([85000.0, 446000.0, 40.0])
GROUND = 0.0
LENS = distortion_from_dict({"model": "brown_conrady", "k1": 2e-3, "k2": -1e-4})


def _camera(projection: str, wide: bool) -> Camera:
    f, ps = (2.0, 0.003) if wide else (3.0, 0.002)
    return Camera("fish", f, ps, 2000, 1500, 0.03, -0.02, LENS, projection)


def _scene(cam: Camera) -> PickingScene:
    eo = ExteriorOrientationTable(("img1",), np.array([np.nan]), ("",), CENTRE[None],
                                  np.radians([[12.0, -5.0, 30.0]]), CRS)  # fmt: skip
    return PickingScene(eo, cam)


def _on_segment(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance (px) of points p from the segments a-b, (K,)."""
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.einsum("ij,ij->i", ab, ab), 0.0, 1.0)
    return np.hypot(*(a + t[:, None] * ab - p).T)


@pytest.mark.parametrize("projection", FISHEYE_PROJECTIONS)
def test_fisheye_footprint_reprojects_to_the_image_border(projection):
    cam = _camera(projection, wide=False)
    scene = _scene(cam)
    fp = scene.footprint("img1", GROUND)
    border = _border(cam.width_px, cam.height_px, FOOTPRINT_BORDER_POINTS)
    assert fp.shape == (len(border), 3) and np.isfinite(fp).all()
    np.testing.assert_allclose(fp[:, 2], GROUND, atol=1e-6)
    back = scene.project("img1", fp)
    err = np.hypot(*(back - border).T)
    assert err.max() < 0.01, err.max()
    # the outline curves on the ground: its mid-side points are off the corners' chords
    corners = fp[::FOOTPRINT_BORDER_POINTS, :2]
    mid = fp[FOOTPRINT_BORDER_POINTS // 2 :: FOOTPRINT_BORDER_POINTS, :2]
    chord = 0.5 * (corners + np.roll(corners, -1, axis=0))
    assert np.hypot(*(mid - chord).T).max() > 1.0


@pytest.mark.parametrize("projection", FISHEYE_PROJECTIONS)
def test_wide_fisheye_footprint_is_the_field_that_reaches_the_ground(projection):
    cam = _camera(projection, wide=True)
    scene = _scene(cam)
    fp = scene.footprint("img1", GROUND)
    border = _border(cam.width_px, cam.height_px, FOOTPRINT_BORDER_POINTS)
    assert np.isfinite(fp).all()
    np.testing.assert_allclose(fp[:, 2], GROUND, atol=1e-6)
    back = scene.project("img1", fp)
    on_border = np.hypot(*(back - border).T) < 0.01
    depth = CENTRE[2] - GROUND
    reach = np.hypot(*(scene.to_local(fp) - scene.local_eo[0, :3])[:, :2].T) / depth
    # moved vertices: at the range limit, inside the frame, between the principal point
    # and their border pixel
    moved = ~on_border
    assert moved.sum() > 10, moved.sum()
    # the whole border of the orthographic one lies beyond its field (r > f)
    assert on_border.sum() > 10 or projection == "orthographic", on_border.sum()
    # the range is taken on the tangent plane: the level surface, 1.3 cm below it 400 m away,
    # is met 0.03 % farther along these grazing rays; or (orthographic, 90 degrees at most)
    # at the edge of the field (1e-5 rad: the bisection stops 1e-12 of the border distance
    # short), where the tilted camera's last ray still reaches the ground
    at_range = np.abs(reach / FOOTPRINT_RANGE - 1.0) < 1e-3
    theta = theta_from_radius(np.hypot(*cam.ideal_from_pixel(back).T) / cam.focal_mm, projection)
    at_edge = (projection == "orthographic") & (theta > np.pi / 2 - 1e-5)
    assert (at_range | at_edge)[moved].all(), np.pi / 2 - theta[moved & ~at_range & ~at_edge]
    assert at_range.sum() > 10
    assert cam.in_frame(back[moved]).all()
    pp = np.broadcast_to(np.asarray(cam.principal_point_px), (int(moved.sum()), 2))
    assert _on_segment(back[moved], pp, border[moved]).max() < 0.01
    assert (reach[on_border] <= FOOTPRINT_RANGE * (1 + 1e-3)).all()


# ----------------------------------------------------------------------------- monoplot
def _dsm(tilted: bool) -> Dsm:
    """200 x 200 m at 1 m around the nadir; the tilted plane rises 1 m per 4 m east and
    falls 1 m per 8 m north (heights multiples of 1/8: exact in float32)."""
    grid = Grid(CENTRE[0] - 100.0, CENTRE[1] + 100.0, 1.0, 200, 200)
    rows, cols = np.mgrid[0:200, 0:200]
    z = GROUND + (0.25 * (cols - 100) + 0.125 * (rows - 100) if tilted else 0.0 * cols)
    return Dsm(z.astype(np.float32), grid)


def _plane_height(dsm: Dsm, xy: np.ndarray) -> np.ndarray:
    """The DSM's own plane at map (x, y): heights at cell centres, linear between them."""
    x0, y0 = dsm.centre_origin
    col = (xy[:, 0] - x0) / dsm.cell
    row = (y0 - xy[:, 1]) / dsm.cell
    return np.asarray(dsm.heights[0, 0], float) + 0.25 * col + 0.125 * row


@pytest.mark.parametrize("tilted", [False, True], ids=["flat", "tilted"])
@pytest.mark.parametrize("projection", FISHEYE_PROJECTIONS)
def test_fisheye_monoplot_lands_on_the_true_ground_point(projection, tilted):
    cam = _camera(projection, wide=False)
    scene = _scene(cam)
    dsm = _dsm(tilted)
    rng = np.random.default_rng(7)
    xy = CENTRE[:2] + rng.uniform(-45.0, 45.0, (300, 2))
    z = _plane_height(dsm, xy) if tilted else np.full(len(xy), GROUND)
    truth = np.column_stack([xy, z])
    px = scene.project("img1", truth)
    keep = np.isfinite(px).all(axis=1) & cam.in_frame(px)
    truth, px = truth[keep], px[keep]
    assert len(px) > 100
    # points far off the axis, where the fisheye is not a perspective camera
    r = np.hypot(*cam.ideal_from_pixel(px).T)
    assert r.max() > 0.7 * cam.focal_mm
    n = len(px)
    obs = ImageObservations.from_arrays(["img1"] * n, [str(k) for k in range(n)], px, 0.5,
                                        ["check"] * n, ["0"] * n)  # fmt: skip
    res = monoplot(obs, cam, scene.eo, dsm, CRS)
    assert (res.status == 0).all()
    err = np.linalg.norm(res.points - truth, axis=1)
    assert err.max() < 1e-6, err.max()
    # the perspective formula with the same focal length misses by metres
    persp = monoplot(obs, dataclasses.replace(cam, projection="perspective"), scene.eo, dsm, CRS)
    assert np.nanmax(np.linalg.norm(persp.points - truth, axis=1)) > 1.0
