"""Rendering of synthetic aerial images (core.simulation.render) against the project's
collinearity chain.

The truth of every geometric check is core.photo.picking.PickingScene (EO in the mapping CRS ->
a local frame at the mean perspective centre -> core.geometry.collinearity.project with the lens
model), independent of the renderer's rays (local frame at the DSM centre, chords in the mapping
CRS, DDA traversal, ray-plane intersections).
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from lidarphoto.core.errors import CrsError, InputError
from lidarphoto.core.geometry.camera import Camera, camera_from_dict
from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
from lidarphoto.core.geometry.grid import Grid
from lidarphoto.core.geometry.planes import fit_plane
from lidarphoto.core.geometry.raycast import chord_rays
from lidarphoto.core.geometry.surface import Dsm
from lidarphoto.core.lidar.control import ControlLine
from lidarphoto.core.lidar.dsm import dsm_from_points
from lidarphoto.core.photo.orientation import ExteriorOrientationTable, eo_map_to_local
from lidarphoto.core.photo.picking import PickingScene
from lidarphoto.core.simulation.render import _Rays, edge_offsets, render_image, render_images
from lidarphoto.core.simulation.render_scene import (
    CLASS_ALBEDO,
    PLANE_TINTS,
    RenderOptions,
    RenderScene,
    lambert,
    sun_vector,
)

CRS = "EPSG:28992"
X0, Y0 = 85000.0, 447000.0  # Delft, RD New


def _table(xyz, opk_deg) -> ExteriorOrientationTable:
    return ExteriorOrientationTable(("img",), np.array([0.0]), ("",),
                                    np.array([xyz], float), np.radians([opk_deg]), CRS)  # fmt: skip


def _project(table, camera, pts) -> np.ndarray:
    return PickingScene(table, camera, CRS).project("img", np.asarray(pts, float))


def _profile_edge(rgb, a, b, inside_rgb, samples=9, reach=4.0, step=0.25):
    """Signed distances (px, positive towards the inside, on the left of a -> b) from the
    segment a-b to the colour edge, read across it at ``samples`` points: a pixel belongs to
    the inside when its colour is nearer ``inside_rgb`` than the outermost pixel's colour
    (the 50 % crossing of an edge blended over part of a pixel)."""
    d = b - a
    u = d / np.linalg.norm(d)
    left = np.array([u[1], -u[0]])  # rows grow downwards: (u_y, -u_x) is on the left
    offs = np.arange(-reach, reach + 1e-9, step)
    out = []
    for t in np.linspace(0.15, 0.85, samples):
        p = a + t * d + offs[:, None] * left[None, :]
        px = rgb[np.floor(p[:, 1]).astype(int), np.floor(p[:, 0]).astype(int)].astype(float)
        to_in = np.linalg.norm(px - inside_rgb, axis=1)
        inside = to_in < np.linalg.norm(px - px[0], axis=1)
        assert inside[-1] and not inside[0], (t, inside)
        k = np.flatnonzero(inside[1:] != inside[:-1])
        assert k.size == 1, (t, inside)
        out.append((offs[k[0]] + offs[k[0] + 1]) / 2)
    return np.array(out)


# ------------------------------------------------------------------------ box house, DSM only
@pytest.fixture(scope="module")
def box():
    """A 8 m x 6 m box house, flat roof 8 m, on ground sloping 5 % to the east; DSM of 2.5 cm
    (0.4 px of the camera below); points on a 0.25 m lattice give the classes."""
    cell = 0.025
    grid = Grid(X0, Y0 + 30.0, cell, 1200, 1200)
    xc = grid.x0 + (np.arange(grid.cols) + 0.5) * cell
    yc = grid.y_top - (np.arange(grid.rows) + 0.5) * cell
    xx, yy = np.meshgrid(xc, yc)
    ground = 0.05 * (xx - X0)
    house = (np.abs(xx - (X0 + 15)) < 4.0) & (np.abs(yy - (Y0 + 15)) < 3.0)
    z = np.where(house, 8.0, ground).astype(np.float32)
    dsm = Dsm(z, grid, MappingFrame.from_user_input(CRS).crs)
    lx, ly = np.meshgrid(np.arange(0.125, 30, 0.25) + X0, np.arange(0.125, 30, 0.25) + Y0)
    on = (np.abs(lx - (X0 + 15)) < 4.0) & (np.abs(ly - (Y0 + 15)) < 3.0)
    pts = np.column_stack([lx.ravel(), ly.ravel(), np.where(on, 8.0, 0.05 * (lx - X0)).ravel()])
    scene = RenderScene.build(dsm, pts, np.where(on, 6, 2).ravel(), crs=CRS)
    corners = np.array([[X0 + 11, Y0 + 12, 8.0], [X0 + 19, Y0 + 12, 8.0],
                        [X0 + 19, Y0 + 18, 8.0], [X0 + 11, Y0 + 18, 8.0]])  # fmt: skip
    return scene, corners


def test_box_house_roof_edges_and_lambert(box):
    scene, corners = box
    cam = Camera("c", focal_mm=10.0, pixel_size_mm=0.01, width_px=320, height_px=256)
    table = _table([X0 + 15.5, Y0 + 14.0, 68.0], [3.0, -2.0, 20.0])
    opt = RenderOptions(step_px=1, noise_dn=0.0)
    img = render_image(scene, cam, table.xyz[0], table.opk[0], opt)
    assert img.rgb.shape == (256, 320, 3) and img.rgb.dtype == np.uint8
    sun = sun_vector(opt.sun_azimuth_deg, opt.sun_elevation_deg)
    roof = np.rint(255 * np.array(CLASS_ALBEDO[6]) * lambert([[0, 0, 1.0]], sun, opt.ambient))
    # the sloping ground: normal (-0.05, 0, 1) normalised, Lambert exactly
    n_ground = np.array([[-0.05, 0.0, 1.0]]) / math.hypot(0.05, 1.0)
    ground = 255 * np.array(CLASS_ALBEDO[2]) * lambert(n_ground, sun, opt.ambient)
    px = _project(table, cam, corners)
    centre = px.mean(axis=0)
    assert np.abs(img.rgb[int(centre[1]), int(centre[0])].astype(int) - roof).max() == 0
    far = _project(table, cam, [[X0 + 15.5, Y0 + 8.0, 0.05 * 15.5]])[0]
    assert cam.in_frame(far[None], 5.0)[0]
    assert np.abs(img.rgb[int(far[1]), int(far[0])] - ground).max() <= 0.51
    # each roof edge: the colour changes from roof to wall/ground within 1 px of its projection
    turn = np.cross(np.r_[px[1] - px[0], 0.0], np.r_[px[2] - px[1], 0.0])[2]
    ccw = px if turn < 0 else px[::-1]  # the roof on the left of each edge (rows go down)
    offsets = np.concatenate([_profile_edge(img.rgb, ccw[k], ccw[(k + 1) % 4], roof)
                              for k in range(4)])  # fmt: skip
    assert np.abs(offsets).max() <= 1.0, offsets
    # around each corner's pixel (5 x 5: the roof is a 90-degree wedge there) both the roof
    # and something else (50 % crossing)
    for c in px:
        win = img.rgb[int(c[1]) - 2 : int(c[1]) + 3, int(c[0]) - 2 : int(c[0]) + 3].reshape(-1, 3)
        is_roof = np.linalg.norm(win - roof, axis=1) < 0.5 * np.linalg.norm(roof - ground)
        assert is_roof.any() and not is_roof.all()


# ------------------------------------------------------------------------ hip roof with planes
def _hip_house(rng, centre, length=12.0, width=8.0, eave=6.0, slope=0.8, turn_deg=25.0):
    """Points of a hip-roof house (faces N, S, E, W in the house frame) and of the ground
    around it, with the exact planes, ridge and hip lines and the two ridge-end corners."""
    c, s = math.cos(math.radians(turn_deg)), math.sin(math.radians(turn_deg))
    rot = np.array([[c, -s], [s, c]])

    def roof(u, v):
        a, b = width / 2 - np.abs(v), length / 2 - np.abs(u)
        face = np.where(a <= b, np.where(v >= 0, 0, 1), np.where(u >= 0, 2, 3))
        return eave + slope * np.minimum(a, b), face

    n = 12 * 40 * 40  # 12 points per m^2 over 40 m x 40 m
    uv = rng.uniform(-20, 20, (n, 2))
    on = (np.abs(uv[:, 0]) < length / 2) & (np.abs(uv[:, 1]) < width / 2)
    z, face = roof(uv[:, 0], uv[:, 1])
    xy = np.asarray(centre) + uv @ rot.T
    zz = np.where(on, z, 0.0)
    pts = np.column_stack([xy, zz])
    cls = np.where(on, 6, 2)
    pid = np.where(on, face, -1)
    planes = [fit_plane(pts[pid == k], plane_id=k) for k in range(4)]
    r = length / 2 - width / 2
    top = eave + slope * width / 2

    def m(u, v, h):
        return np.r_[np.asarray(centre) + rot @ [u, v], h]

    ends = (m(-r, 0, top), m(r, 0, top))
    segs = {
        (0, 1): ends,
        (0, 2): (ends[1], m(length / 2, width / 2, eave)),
        (1, 2): (ends[1], m(length / 2, -width / 2, eave)),
        (0, 3): (ends[0], m(-length / 2, width / 2, eave)),
        (1, 3): (ends[0], m(-length / 2, -width / 2, eave)),
    }
    lines = []
    for k, ((a, b), (p, q)) in enumerate(segs.items()):
        u = (q - p) / np.linalg.norm(q - p)
        lines.append(ControlLine(k + 1, (a, b), "hip" if k else "ridge", p, q, p, u,
                                 np.zeros((6, 6)), 90.0))  # fmt: skip
    corners = {(0, 1, 2): ends[1], (0, 1, 3): ends[0]}
    return pts, cls, pid, planes, lines, corners


@pytest.fixture(scope="module")
def hip():
    rng = np.random.default_rng(3)
    centre = (X0 + 20.0, Y0 + 20.0)
    pts, cls, pid, planes, lines, corners = _hip_house(rng, centre)
    heights, grid = dsm_from_points(pts[:, 0], pts[:, 1], pts[:, 2], 0.5)
    dsm = Dsm(heights, grid, MappingFrame.from_user_input(CRS).crs)
    scene = RenderScene.build(dsm, pts, cls, pid, planes, lines, crs=CRS)
    # a lens with radial distortion: the renderer and the truth both go through it
    cam = camera_from_dict({"name": "k1", "focal_mm": 35.0, "pixel_size_mm": 0.0045,
                            "width_px": 1600, "height_px": 1200,
                            "distortion": {"model": "brown_conrady", "k1": 8e-5}})  # fmt: skip
    table = _table([centre[0] + 4.0, centre[1] - 3.0, 120.0], [1.5, -2.5, 35.0])
    img = render_image(scene, cam, table.xyz[0], table.opk[0], RenderOptions(step_px=4))
    return scene, cam, table, img, planes, lines, corners


def test_hip_roof_edges_on_the_projected_lines(hip):
    _scene, cam, table, img, _planes, lines, corners = hip
    ends = _project(table, cam, np.array([[ln.start, ln.end] for ln in lines]).reshape(-1, 3))
    off, which = edge_offsets(img.plane_id, ends[0::2], ends[1::2],
                              [ln.plane_ids for ln in lines])  # fmt: skip
    assert set(which.tolist()) == set(range(len(lines)))  # every line was crossed
    assert off.size >= 50 and np.abs(off).max() <= 1.0, np.abs(off).max()
    # each ridge-end corner (an LCP) is where its three planes meet, within 1.5 px
    for ids, xyz in corners.items():
        c = _project(table, cam, [xyz])[0]
        win = img.plane_id[int(c[1]) - 1 : int(c[1]) + 3, int(c[0]) - 1 : int(c[0]) + 3]
        assert set(ids) <= set(np.unique(win).tolist()), (ids, np.unique(win))


def test_hip_roof_colours_are_the_plane_tints_under_lambert(hip):
    scene, _cam, _table, img, planes, *_ = hip
    opt = RenderOptions()
    sun = sun_vector(opt.sun_azimuth_deg, opt.sun_elevation_deg)
    tints = [scene.tint[k] for k in range(4)]
    assert len(set(tints)) == 4  # the four faces of one roof touch each other: four tints
    rng = np.random.default_rng(0)
    for k, plane in enumerate(planes):
        want = 255 * np.array(PLANE_TINTS[tints[k]]) * lambert([plane.normal], sun, opt.ambient)
        rows, cols = np.nonzero(img.plane_id == plane.id)
        assert rows.size > 1000
        pick = rng.choice(rows.size, 500, replace=False)
        got = img.rgb[rows[pick], cols[pick]].astype(float)
        # luminance noise of 1 DN: the mean within 0.2 DN (+ 0.5 rounding), the spread as put
        # in (+ rounding), the same on the three channels
        assert np.abs(got.mean(axis=0) - want).max() < 0.2 + 0.5
        assert 0.8 < got.std(axis=0).mean() < 1.3
        assert np.corrcoef(got.T).min() > 0.8


def test_ray_directions_interpolated_within_a_microradian(hip):
    scene, cam, table, *_ = hip
    rays = _Rays.build(scene, cam, table.xyz[0], table.opk[0], 16)
    rng = np.random.default_rng(1)
    pix = rng.uniform([0, 0], [cam.width_px, cam.height_px], (400, 2))
    got = rays.at(pix[:, 0], pix[:, 1])
    # exact: the chord of each pixel's own ENU ray, as core.photo.monoplot builds it
    dsm = scene.dsm
    xc = dsm.grid.x0 + dsm.grid.cols * dsm.cell / 2
    yc = dsm.grid.y_top - dsm.grid.rows * dsm.cell / 2
    local = LocalFrame.at_map_point(MappingFrame.from_user_input(CRS), [xc, yc, scene.tracer.zmin])
    c_loc, m_loc = eo_map_to_local(table.xyz, table.opk, local)
    ray = np.column_stack([cam.ideal_from_pixel(pix), np.full(400, -cam.focal_mm)]) @ m_loc[0]
    ray /= np.linalg.norm(ray, axis=1, keepdims=True)
    low = local.map_to_enu(np.array([[xc, yc, scene.tracer.zmin - 10.0]]))[0, 2]
    exact = chord_rays(local, np.repeat(table.xyz, 400, 0), np.repeat(c_loc, 400, 0), ray,
                        (c_loc[0, 2] - low) / -ray[:, 2])  # fmt: skip
    angle = np.arccos(np.clip(np.einsum("ij,ij->i", got, exact), -1, 1))
    assert angle.max() < 1e-6
    grid = rays.on_grid(pix[:5, 0], pix[:7, 1]).reshape(7, 5, 3)
    np.testing.assert_allclose(grid[3, 2], rays.at(pix[2:3, 0], pix[3:4, 1])[0], atol=1e-12)


def test_render_images_writes_rgb_tiffs(hip, tmp_path):
    scene, _cam, table, *_ = hip
    small = Camera("s", focal_mm=35.0, pixel_size_mm=0.018, width_px=400, height_px=300)
    opt = RenderOptions(noise_dn=0.0)
    paths = render_images(scene, small, table, tmp_path, options=opt)
    assert list(paths) == ["img"] and paths["img"].name == "img.tif"
    back = cv2.cvtColor(cv2.imread(str(paths["img"]), cv2.IMREAD_UNCHANGED), cv2.COLOR_BGR2RGB)
    direct = render_image(scene, small, table.xyz[0], table.opk[0], opt)
    np.testing.assert_array_equal(back, direct.rgb)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["img.tif"]  # no temporary file left
    with pytest.raises(InputError, match="no exterior orientation"):
        render_images(scene, small, table, tmp_path, image_ids=["nope"])
    other = ExteriorOrientationTable(("img",), table.time, ("",), table.xyz, table.opk,
                                     "EPSG:32631")  # fmt: skip
    with pytest.raises(CrsError):
        render_images(scene, small, other, tmp_path)
    with pytest.raises(InputError, match="step_px"):
        RenderOptions(step_px=0)
