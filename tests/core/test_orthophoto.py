"""Orthophotos (core.photo.orthophoto) against truth.

The exact case: an image rendered by core.simulation.render from a textured DSM (a box house on
sloping ground with a checkerboard of surface classes) with a known orientation and a lens with
radial distortion. Truths, each computed without the orthophoto's code:

- geometry: the renderer's own ray through the image position the orthophoto samples for a
  cell (its direction field and DDA, core.simulation.render) must come back to the cell's
  ground point;
- texture: the colour the renderer gives a ground point (class albedo x Lambert shading of the
  DSM face) must be reproduced, with no shift (phase correlation);
- occlusion: a cell is hidden when the renderer's ray towards it stops earlier; and,
  independently of any ray casting, when the straight segment from the camera to the cell
  dips below the DSM surface (dense sampling of Dsm.height_at along it).

The projection chain is checked against core.geometry.collinearity.project with every cell
brought into the ENU frame through pyproj one by one (far from a UTM zone's central meridian,
with a km-wide footprint), and the numba and numpy back ends against each other.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera, camera_from_dict
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.geometry.grid import Grid
from lidarphoto.core.geometry.raycast import intersect_dsm
from lidarphoto.core.geometry.rotations import matrix_to_opk
from lidarphoto.core.geometry.surface import Dsm
from lidarphoto.core.photo.orientation import eo_map_to_local
from lidarphoto.core.photo.orthophoto import (
    OrthoOptions,
    OrthoProjector,
    auto_gsd,
    ortho_grid,
    orthorectify_tiles,
)
from lidarphoto.core.photo.orthophoto_numba import AVAILABLE as NUMBA
from lidarphoto.core.quality.registration import phase_correlation
from lidarphoto.core.simulation.render import _Rays, render_image
from lidarphoto.core.simulation.render_scene import RenderOptions, RenderScene, lambert, sun_vector

CRS = "EPSG:28992"
X0, Y0 = 85000.0, 447000.0
GSD = 0.06


def _scene():
    """A 8 m x 6 m box house (flat roof at 8 m) on ground sloping 5 % to the east, DSM cells of
    0.1 m; the ground's classes form a 1 m checkerboard of grey-green (2) and water blue (9)."""
    cell = 0.1
    grid = Grid(X0, Y0 + 40.0, cell, 400, 400)
    xc = grid.x0 + (np.arange(grid.cols) + 0.5) * cell
    yc = grid.y_top - (np.arange(grid.rows) + 0.5) * cell
    xx, yy = np.meshgrid(xc, yc)
    house = (np.abs(xx - (X0 + 20)) < 4.0) & (np.abs(yy - (Y0 + 20)) < 3.0)
    z = np.where(house, 8.0, 0.05 * (xx - X0)).astype(np.float32)
    dsm = Dsm(z, grid, MappingFrame.from_user_input(CRS).crs)
    checker = ((np.floor(xx - X0) + np.floor(yy - Y0)) % 2).astype(int)
    cls = np.where(house, 6, np.where(checker == 0, 2, 9))
    pts = np.column_stack([xx.ravel(), yy.ravel(), z.ravel()])
    scene = RenderScene.build(dsm, pts, cls.ravel(), crs=CRS)
    return scene, dsm


@pytest.fixture(scope="module")
def exact():
    return exact_case()


def exact_case() -> dict:
    """The exact case (module docstring): the rendered image, its orthophotos (plain and
    true) and every truth; bench/bench_ortho.py reports its figures."""
    scene, dsm = _scene()
    cam = camera_from_dict({"name": "k1", "focal_mm": 10.0, "pixel_size_mm": 0.01,
                            "width_px": 800, "height_px": 600,
                            "distortion": {"model": "brown_conrady", "k1": 2e-4}})  # fmt: skip
    xyz = np.array([X0 + 14.0, Y0 + 12.0, 60.0])
    opk = np.radians([3.0, -2.0, 20.0])
    opt = RenderOptions(step_px=1, noise_dn=0.0)
    img = render_image(scene, cam, xyz, opk, opt)
    proj = OrthoProjector.build(cam, xyz, opk, dsm, CRS)
    grid = ortho_grid(proj.footprint(), GSD)

    read = _reader(np.moveaxis(img.rgb, 2, 0))

    def ortho(**kw):
        o = OrthoOptions(gsd=GSD, tile_px=128, **kw)
        data = np.zeros((3, grid.rows, grid.cols), np.uint8)
        valid = np.zeros((grid.rows, grid.cols), bool)
        for t in orthorectify_tiles(proj, grid, read, 3, np.uint8, o):
            h, w = t.valid.shape
            data[:, t.row0 : t.row0 + h, t.col0 : t.col0 + w] = t.data
            valid[t.row0 : t.row0 + h, t.col0 : t.col0 + w] = t.valid
        return data, valid

    plain, plain_valid = ortho(true_ortho=False)
    true_, true_valid = ortho(true_ortho=True)
    col, row, z = proj.pixels(grid, 0, 0, grid.rows, grid.cols)
    xs = grid.x0 + (np.arange(grid.cols) + 0.5) * GSD
    ys = grid.y_top - (np.arange(grid.rows) + 0.5) * GSD
    gx, gy = np.meshgrid(xs, ys)
    # the renderer's rays through the sampled image positions: where do they land?
    rays = _Rays.build(scene, cam, xyz, opk, opt.direction_grid_px)
    ok = np.isfinite(col)
    dirs = rays.at(col[ok], row[ok])
    hits = intersect_dsm(scene.tracer, np.broadcast_to(xyz, dirs.shape), dirs,
                         min_incidence_deg=0.0)  # fmt: skip
    land = np.full((grid.rows, grid.cols, 3), np.nan)
    land[ok] = hits.points
    ground = np.dstack([gx, gy, z])
    gap = np.linalg.norm(land - ground, axis=2)  # cells: how far the renderer's ray lands
    dist_g = np.linalg.norm(ground - xyz, axis=2)
    dist_h = np.linalg.norm(land - xyz, axis=2)
    hidden = ok & (dist_h < dist_g - 0.05)
    # the texture the renderer gives each ground point (face normal of the DSM under it)
    above = np.column_stack([gx[ok], gy[ok], np.full(ok.sum(), 100.0)])
    down = intersect_dsm(dsm, above, np.tile([0.0, 0.0, -1.0], (above.shape[0], 1)),
                         min_incidence_deg=0.0)  # fmt: skip
    normal = np.column_stack([-down.gradient, np.ones(above.shape[0])])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    sun = sun_vector(opt.sun_azimuth_deg, opt.sun_elevation_deg)
    truth = np.full((grid.rows, grid.cols, 3), np.nan)
    truth[ok] = 255 * scene.albedo_at(gx[ok], gy[ok]) * lambert(normal, sun, opt.ambient)[:, None]
    return {"cam": cam, "xyz": xyz, "opk": opk, "dsm": dsm, "proj": proj, "grid": grid,
            "plain": plain, "plain_valid": plain_valid, "true": true_, "true_valid": true_valid,
            "col": col, "row": row, "z": z, "gap": gap, "hidden": hidden, "truth": truth,
            "gx": gx, "gy": gy, "img": img}  # fmt: skip


def _reader(image: np.ndarray):
    """read_window of an in-memory (bands, rows, cols) image, f x f means as GDAL's average."""

    def read(win, f=1):
        c0, r0, w, h = win
        block = image[:, r0 : r0 + h, c0 : c0 + w]
        if f == 1:
            return block
        b = block.reshape(block.shape[0], h // f, f, w // f, f).mean(axis=(2, 4))
        return np.rint(b).astype(image.dtype) if image.dtype.kind in "ui" else b.astype(
            image.dtype)  # fmt: skip

    return read


def _interior(mask: np.ndarray, px: int) -> np.ndarray:
    """Cells of ``mask`` at least ``px`` cells from its border."""
    k = np.ones((2 * px + 1, 2 * px + 1), np.uint8)
    return cv2.erode(mask.astype(np.uint8), k, borderValue=0).astype(bool)


def test_cells_sample_where_the_renderer_saw_them(exact):
    e = exact
    ground = (e["z"] < 3.0) & np.isfinite(e["col"]) & ~e["hidden"]
    roof = (e["z"] > 7.9) & np.isfinite(e["col"])
    for region in (ground, roof):
        keep = _interior(region, 3)
        assert keep.sum() > 5000
        err_px = e["gap"][keep] / GSD
        rms = float(np.sqrt(np.mean(err_px**2)))
        # the renderer's rays are chords to a point below the scene, 5e-6 rad off the chord to
        # the cell itself (0.3 mm at 60 m: 0.005 cell); the orthophoto's chain agrees with
        # per-point collinearity to 5e-4 px (test below)
        assert rms < 0.02 and err_px.max() < 0.05, (rms, err_px.max())


def test_texture_reproduced_without_shift(exact):
    e = exact
    gray = lambda a: a.astype(np.float64) @ np.array([0.299, 0.587, 0.114])  # noqa: E731
    ortho = gray(np.moveaxis(e["plain"], 0, 2))
    truth = gray(np.nan_to_num(e["truth"]))
    keep = _interior(e["plain_valid"] & (e["z"] < 3.0) & ~e["hidden"], 4)
    rows, cols = np.nonzero(keep)
    r0, r1, c0, c1 = rows.min(), rows.max(), cols.min(), cols.max()
    # the largest square of ground inside: phase correlation over it
    best = None
    for size in (256, 192, 128):
        for rr in range(r0, r1 - size, 16):
            for cc in range(c0, c1 - size, 16):
                if keep[rr : rr + size, cc : cc + size].all():
                    best = (rr, cc, size)
                    break
            if best:
                break
        if best:
            break
    assert best is not None
    rr, cc, size = best
    a = ortho[rr : rr + size, cc : cc + size]
    b = truth[rr : rr + size, cc : cc + size]
    dx, dy, peak = phase_correlation(b, a)
    assert math.hypot(dx, dy) < 0.05 and peak > 0.9, (dx, dy, peak)
    # the registration itself recovers a known shift of the truth (bicubic) to 0.03 px
    shifted = cv2.warpAffine(truth.astype(np.float32), np.float32([[1, 0, 0.37], [0, 1, -0.2]]),
                             truth.shape[::-1], flags=cv2.INTER_CUBIC)  # fmt: skip
    sx, sy, _ = phase_correlation(b, shifted[rr : rr + size, cc : cc + size])
    assert abs(sx - 0.37) < 0.03 and abs(sy + 0.2) < 0.03, (sx, sy)
    # away from the checker edges (bilinear blur of one image pixel), equal to quantisation
    squares = (np.floor(e["gx"] - X0) + np.floor(e["gy"] - Y0)) % 2
    flat = _interior(keep & (squares == 0), 3) | _interior(keep & (squares == 1), 3)
    diff = ortho[flat] - truth[flat]
    assert flat.sum() > 3000
    assert np.sqrt(np.mean(diff**2)) < 0.6 and np.abs(diff).max() < 1.5


def test_true_ortho_flags_what_the_renderer_hides(exact):
    e = exact
    both = e["plain_valid"]
    occluded = both & ~e["true_valid"]
    hidden = e["hidden"] & both
    assert hidden.sum() > 2000  # the house hides a good strip of ground
    # cells one cell or more away from the border between hidden and seen agree exactly
    border = cv2.dilate(hidden.astype(np.uint8), np.ones((3, 3), np.uint8)) != cv2.erode(
        hidden.astype(np.uint8), np.ones((3, 3), np.uint8))  # fmt: skip
    sure = both & ~border
    assert np.array_equal(occluded[sure], hidden[sure])
    assert abs(int(occluded.sum()) - int(hidden.sum())) < 0.02 * hidden.sum()
    # visible cells keep the plain orthophoto's values
    np.testing.assert_array_equal(e["true"][:, e["true_valid"]], e["plain"][:, e["true_valid"]])


def test_occlusion_against_dense_sampling_of_the_segment(exact):
    """No ray casting: sample the segment camera -> cell every 1/8 DSM cell; hidden when a
    sample (beyond 0.2 m from the cell) lies below the surface."""
    e = exact
    dsm, xyz = e["dsm"], e["xyz"]
    rng = np.random.default_rng(4)
    valid = e["plain_valid"].ravel()
    # half among the cells found occluded, half among the others within 12 m of the house
    near = (np.abs(e["gx"] - (X0 + 20)) < 16) & (np.abs(e["gy"] - (Y0 + 20)) < 15)
    occ = np.flatnonzero(valid & ~e["true_valid"].ravel())
    vis = np.flatnonzero(valid & e["true_valid"].ravel() & near.ravel())
    pick = np.r_[rng.choice(occ, 1500, replace=False), rng.choice(vis, 1500, replace=False)]
    g = np.column_stack([e["gx"].ravel()[pick], e["gy"].ravel()[pick], e["z"].ravel()[pick]])
    d = xyz - g
    length = np.linalg.norm(d, axis=1)
    s = np.arange(0.2, 15.0, dsm.cell / 8)  # the segment is above the roof (8 m) by then
    pts = g[:, None, :] + (s[None, :, None] / length[:, None, None]) * d[:, None, :]
    inside = s[None, :] < length[:, None]
    below = (pts[..., 2] < dsm.height_at(pts[..., 0].ravel(), pts[..., 1].ravel()).reshape(
        pts.shape[:2]) - 1e-6) & inside  # fmt: skip
    truth = below.any(axis=1)
    got = ~e["true_valid"].ravel()[pick]
    agree = truth == got
    assert truth.sum() > 1000
    # sampling misses grazing slivers thinner than 1/8 cell: allow a handful near the edges
    assert agree.mean() > 0.995, (agree.mean(), int((~agree).sum()))


@pytest.mark.skipif(not NUMBA, reason="numba not installed")
def test_numba_and_numpy_back_ends_agree(exact):
    proj, grid = exact["proj"], exact["grid"]
    a = proj.pixels(grid, 37, 11, 200, 150, backend="numba")
    b = proj.pixels(grid, 37, 11, 200, 150, backend="numpy")
    for u, v in zip(a, b):
        np.testing.assert_array_equal(np.isnan(u), np.isnan(v))
        np.testing.assert_allclose(u[np.isfinite(u)], v[np.isfinite(v)], rtol=0, atol=1e-9)


@pytest.mark.skipif(not NUMBA, reason="numba not installed")
def test_numba_and_numpy_back_ends_agree_without_lens(exact):
    """The compiled loop without a lens (its vectorised path) against numpy, on a block that
    reaches beyond the DSM and the image on every side, and on a lattice interval that does
    not divide the block."""
    proj, grid = exact["proj"], exact["grid"]
    cam = Camera("ideal", focal_mm=10.0, pixel_size_mm=0.01, width_px=800, height_px=600)
    ideal = OrthoProjector.build(cam, proj.xyz, proj.opk, proj.dsm, CRS)
    assert ideal.lens[0].shape[0] == 1  # no lens lattice
    r0, c0 = -40, -30  # rows and columns before the grid: beyond the DSM
    h, w = grid.rows + 80, grid.cols + 70
    for step in (64, 37):
        a = ideal.pixels(grid, r0, c0, h, w, lattice_px=step, backend="numba")
        b = ideal.pixels(grid, r0, c0, h, w, lattice_px=step, backend="numpy")
        assert np.isnan(a[2]).any() and np.isfinite(a[2]).mean() > 0.5
        assert np.isnan(a[0][np.isfinite(a[2])]).any()  # on the DSM, off the image
        for u, v in zip(a, b):
            np.testing.assert_array_equal(np.isnan(u), np.isnan(v))
            np.testing.assert_allclose(u[np.isfinite(u)], v[np.isfinite(v)], rtol=0, atol=1e-9)


def test_projection_chain_exact_far_from_the_central_meridian():
    """UTM 31N at 0.5 deg E (2.5 deg west of the central meridian, scale 1.0008), a 1.4 km
    footprint at 1 m cells, a hilly DSM: every cell against collinearity in the ENU frame with
    its own pyproj transformation."""
    crs = "EPSG:32631"
    mapping = MappingFrame.from_user_input(crs)
    e0, n0, _ = mapping.geodetic_to_map(np.array([[48.0, 0.5, 0.0]]))[0]
    cell = 2.0
    grid = Grid(round(e0) - 1000.0, round(n0) + 1000.0, cell, 1000, 1000)
    xc = grid.x0 + (np.arange(grid.cols) + 0.5) * cell
    yc = grid.y_top - (np.arange(grid.rows) + 0.5) * cell
    xx, yy = np.meshgrid(xc, yc)
    z = (150 + 40 * np.sin((xx - e0) / 300) * np.cos((yy - n0) / 200)).astype(np.float32)
    dsm = Dsm(z, grid, mapping.crs)
    cam = camera_from_dict({"name": "wide", "focal_mm": 50.0, "pixel_size_mm": 0.0052,
                            "width_px": 11608, "height_px": 8708,
                            "distortion": {"model": "brown_conrady", "k1": 3e-5, "k2": -1e-8,
                                           "p1": 2e-6}})  # fmt: skip
    xyz = np.array([e0 + 30.0, n0 - 20.0, 1400.0])
    opk = np.radians([2.0, 1.5, 33.0])
    proj = OrthoProjector.build(cam, xyz, opk, dsm, crs)
    og = ortho_grid(proj.footprint(), 1.0)
    rng = np.random.default_rng(7)
    rows = rng.integers(0, og.rows - 400, 8)
    cols = rng.integers(0, og.cols - 400, 8)
    checked = 0
    for r0, c0 in zip(rows, cols):
        col, row, zz = proj.pixels(og, int(r0), int(c0), 300, 300)
        ok = np.isfinite(col)
        ii, jj = np.nonzero(ok)
        if ii.size < 1000:  # a corner of the footprint's box, off the image
            continue
        sel = rng.choice(ii.size, min(ii.size, 3000), replace=False)
        ii, jj = ii[sel], jj[sel]
        pts = np.column_stack([og.x0 + (c0 + jj + 0.5) * og.cell,
                               og.y_top - (r0 + ii + 0.5) * og.cell, zz[ii, jj]])  # fmt: skip
        local = proj.local
        c_loc, m_loc = eo_map_to_local(xyz[None], opk[None], local)
        w, p, k = matrix_to_opk(m_loc[0])
        eo_loc = np.r_[c_loc[0], w, p, k]
        exact_px = project(local.map_to_enu(pts), eo_loc, cam)
        got = np.column_stack([col[ii, jj], row[ii, jj]])
        err = np.abs(got - exact_px).max()
        assert err < 2e-3, err  # the lens lattice (< 1e-3 px) and the a, b lattice
        checked += ii.size
    assert checked > 9000
    # the heights are those of the DSM surface
    np.testing.assert_allclose(zz[ii, jj], dsm.height_at(pts[:, 0], pts[:, 1]), atol=1e-4)


@pytest.mark.parametrize("gsd", [0.05, 0.25])
def test_remap_reproduces_a_linear_image(gsd):
    """An image whose value is linear in (col, row): the orthophoto's value at a cell is that
    function at the cell's image position, up to OpenCV's 1/32-pixel interpolation steps. At
    0.25 m a cell spans 4 image pixels: the image is read as 4 x 4 means (a linear function
    is its own mean over a square centred on the point), so the steps are 4 times coarser."""
    _, dsm = _scene()
    cam = Camera("c", focal_mm=10.0, pixel_size_mm=0.01, width_px=800, height_px=600)
    xyz = np.array([X0 + 21.0, Y0 + 18.0, 60.0])
    proj = OrthoProjector.build(cam, xyz, np.radians([1.0, 2.0, -15.0]), dsm, CRS)
    grid = ortho_grid(proj.footprint(), gsd)
    f = 4 if gsd > 0.1 else 1
    cc, rr = np.meshgrid(np.arange(800) + 0.5, np.arange(600) + 0.5)
    img = (10.0 * cc + 3.0 * rr).astype(np.float32)[None]

    read = _reader(img)

    col, row, _ = proj.pixels(grid, 0, 0, grid.rows, grid.cols)
    expected = 10.0 * col + 3.0 * row
    checked = 0
    for tile in orthorectify_tiles(proj, grid, read, 1, np.float32, OrthoOptions(tile_px=100)):
        h, w = tile.valid.shape
        want = expected[tile.row0 : tile.row0 + h, tile.col0 : tile.col0 + w]
        inner = tile.valid & (np.isfinite(want))
        # away from the image border (replicated there)
        sub_c = col[tile.row0 : tile.row0 + h, tile.col0 : tile.col0 + w]
        sub_r = row[tile.row0 : tile.row0 + h, tile.col0 : tile.col0 + w]
        inner &= (sub_c > 2 * f) & (sub_c < 800 - 2 * f) & (sub_r > 2 * f) & (sub_r < 600 - 2 * f)
        if not inner.any():
            continue
        err = np.abs(tile.data[0][inner] - want[inner])
        assert err.max() <= f * (10.0 + 3.0) / 64 + 1e-3
        checked += int(inner.sum())
    assert checked > 0.5 * grid.rows * grid.cols


def test_cells_wider_than_pixels_are_not_aliased():
    """A checkerboard of single pixels (0, 200) seen at 4 pixels per cell: averaged, every
    cell is near 100; resampled without averaging, it swings between the two."""
    _, dsm = _scene()
    cam = Camera("c", focal_mm=10.0, pixel_size_mm=0.01, width_px=800, height_px=600)
    proj = OrthoProjector.build(cam, [X0 + 21.0, Y0 + 18.0, 60.0], np.radians([1, 2, -15.0]),
                                dsm, CRS)  # fmt: skip
    grid = ortho_grid(proj.footprint(), 0.25)
    cc, rr = np.meshgrid(np.arange(800), np.arange(600))
    img = (200 * ((cc + rr) % 2)).astype(np.uint8)[None]
    spread = {}
    for antialias in (True, False):
        vals = np.concatenate([t.data[0][t.valid] for t in orthorectify_tiles(
            proj, grid, _reader(img), 1, np.uint8, OrthoOptions(antialias=antialias))])  # fmt: skip
        spread[antialias] = np.percentile(vals, [5, 95])
    assert 95 <= spread[True][0] and spread[True][1] <= 105, spread
    assert spread[False][1] - spread[False][0] > 100, spread


def test_auto_gsd_and_grid_alignment():
    cam = Camera("c", focal_mm=35.0, pixel_size_mm=0.0045, width_px=6000, height_px=4000)
    assert auto_gsd(cam, 130.0, 0.0) == 0.017
    assert auto_gsd(cam, 1300.0, 0.0) == 0.17
    g = ortho_grid((100.01, 200.02, 150.0, 260.0), 0.25)
    assert g.x0 % 0.25 == 0 and g.y_top % 0.25 == 0
    assert g.x0 <= 100.01 and g.x0 + g.cols * 0.25 >= 150.0
    assert g.y_top >= 260.0 and g.y_top - g.rows * 0.25 <= 200.02


@pytest.mark.parametrize("interp", [cv2.INTER_LINEAR, cv2.INTER_CUBIC])
def test_fixed_point_maps_give_opencvs_own_result(interp):
    """The maps made in one pass in OpenCV's fixed-point form (what cv2.remap makes of float
    maps itself) resample exactly as the float maps: every pixel equal, on positions that
    include exact ties of the 1/32 rounding (half to even), negative and missing ones."""
    from lidarphoto.core.photo.orthophoto_numba import remap_maps, remap_maps_fixed

    rng = np.random.default_rng(5)
    src = rng.integers(0, 256, (300, 400, 3), dtype=np.uint8)
    c0, r0 = 1000, 2000
    col = c0 + rng.uniform(-3.0, 405.0, (256, 256))
    row = r0 + rng.uniform(-3.0, 305.0, (256, 256))
    col[:8] = c0 + 0.5 + np.arange(8)[:, None] / 64.0 + np.arange(256) // 7  # ties at 1/64
    row[:, :8] = r0 + 0.5 + np.arange(8)[None, :] / 64.0
    col[100:110, 50:90] = np.nan
    fx, fy = remap_maps(col, row, c0, r0)
    xy, alpha = remap_maps_fixed(col, row, c0, r0)
    ref_xy, ref_alpha = cv2.convertMaps(fx, fy, cv2.CV_16SC2)
    np.testing.assert_array_equal(xy, ref_xy)
    np.testing.assert_array_equal(alpha, ref_alpha)
    a = cv2.remap(src, fx, fy, interp, borderMode=cv2.BORDER_REPLICATE)
    b = cv2.remap(src, xy, alpha, interp, borderMode=cv2.BORDER_REPLICATE)
    np.testing.assert_array_equal(a, b)


def test_tiles_take_their_nodes_from_the_whole_grids_lattice(exact):
    """A tile that starts on a node takes its lattice from the whole grid's (made once): the
    same nodes as its own, to rounding; a block off the nodes gets its own."""
    proj, grid = exact["proj"], exact["grid"]
    fresh = OrthoProjector.build(proj.camera, proj.xyz, proj.opk, proj.dsm, CRS)
    for r0, c0, h, w in [(128, 64, 128, 128), (0, 0, grid.rows, grid.cols),
                         (grid.rows - 5, 0, 5, 70)]:  # fmt: skip
        ny, nx = max(2, -(-(h - 1) // 64) + 1), max(2, -(-(w - 1) // 64) + 1)
        got = fresh._lattice(grid, r0, c0, h, w, 64)
        own = fresh._nodes(grid, r0, c0, ny, nx, 64)
        np.testing.assert_allclose(got, own, rtol=1e-13, atol=1e-9)
        assert np.shares_memory(got, fresh._lattices[grid, 64]) == (r0 % 64 == 0)
    assert list(fresh._lattices) == [(grid, 64)]


@pytest.mark.skipif(not NUMBA, reason="numba not installed")
def test_cell_stats_compiled_and_numpy_agree(monkeypatch):
    """The tile's one-pass statistics (valid cells, their count and pixel bounds, cells
    without a height) against numpy, with and without valid cells."""
    from lidarphoto.core.photo import orthophoto_numba as k

    rng = np.random.default_rng(3)
    col, row, z = (rng.uniform(-5, 900, (40, 50)) for _ in range(3))
    col[rng.random(col.shape) < 0.3] = np.nan
    z[rng.random(z.shape) < 0.2] = np.nan
    cases = [(col, row, z), (np.full_like(col, np.nan), row, np.full_like(z, np.nan))]
    for c, r, h in cases:
        got = k.cell_stats(c, r, h)
        monkeypatch.setattr(k, "AVAILABLE", False)
        want = k.cell_stats(c, r, h)
        monkeypatch.setattr(k, "AVAILABLE", True)
        np.testing.assert_array_equal(got[0], np.isfinite(c))
        np.testing.assert_array_equal(want[0], np.isfinite(c))
        assert got[1:] == want[1:]
        assert got[1] == np.isfinite(c).sum() and got[2] == np.isnan(h).sum()
    assert got[3] == math.inf  # the last case has no valid cell: infinite bounds


@pytest.mark.parametrize(("workers", "ahead"), [(1, 1), (2, 8), (3, 2)])
def test_ordered_map_keeps_order_and_bounds_the_work_in_flight(workers, ahead):
    import threading

    from lidarphoto.core.errors import Cancelled
    from lidarphoto.core.photo.orthophoto import ordered_map

    lock = threading.Lock()
    started = [0]

    def f(x):
        with lock:
            started[0] += 1
        return x * x

    got = []
    for k, y in enumerate(ordered_map(f, range(50), workers, ahead=ahead)):
        got.append(y)
        with lock:  # started but not yet handed over, this one included
            assert started[0] - k <= ahead * workers
    assert got == [x * x for x in range(50)]
    with pytest.raises(Cancelled):
        list(ordered_map(f, range(50), workers, should_stop=lambda: True, ahead=ahead))
