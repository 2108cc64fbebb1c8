"""Orthophotos of fisheye images against truth (the exact case of test_orthophoto, seen by a
fisheye camera of each projection, Brown k1 added, flown low and tilted over the textured DSM
so that the scene spans up to 60-70 degrees off the optical axis).

Truths, each computed without the orthophoto's code:

- geometry: the camera's own back-projection (lens removed, the projection's ray of the ideal
  point, the chord to the DSM in the mapping frame as the renderer builds it) through the image
  position the orthophoto samples for a cell must land on the cell's ground point (the issue's
  target: within 0.02 cell); and that position equals the per-point forward model
  (core.geometry.collinearity.project of the cell brought into the ENU frame through pyproj);
- texture: the image rendered with those rays, orthorectified, reproduces the colour the
  renderer gives each ground point, with no shift (phase correlation);
- occlusion: a cell is hidden when the exact ray towards it stops earlier;
- the perspective formula with the same focal length would put the cells many pixels away.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera, camera_from_dict
from lidarphoto.core.geometry.collinearity import project_with_status
from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
from lidarphoto.core.geometry.raycast import chord_rays, intersect_dsm
from lidarphoto.core.geometry.rotations import matrix_to_opk
from lidarphoto.core.photo.orientation import eo_map_to_local
from lidarphoto.core.photo.orthophoto import (
    OrthoOptions,
    OrthoProjector,
    ortho_grid,
    orthorectify_tiles,
)
from lidarphoto.core.quality.registration import phase_correlation
from lidarphoto.core.simulation.render import render_image
from lidarphoto.core.simulation.render_scene import RenderOptions, lambert, sun_vector
from test_orthophoto import CRS, GSD, X0, Y0, _interior, _reader, _scene

#: Focal length (mm) per projection: the image corners (5 mm from the centre) 80 degrees off
#: the axis (65 for the orthographic projection, whose field ends at 90).
FOCAL = {"equidistant": 3.58, "equisolid": 3.89, "orthographic": 5.5, "stereographic": 2.98}


def fisheye(projection: str) -> Camera:
    """800 x 600 px of 10 um, principal point off the centre, Brown k1 (mm^-2)."""
    return camera_from_dict({"name": "fish", "focal_mm": FOCAL[projection],
                             "pixel_size_mm": 0.01, "width_px": 800, "height_px": 600,
                             "projection": projection, "x0_mm": 0.05, "y0_mm": -0.03,
                             "distortion": {"model": "brown_conrady", "k1": 1e-3}})  # fmt: skip


XYZ = np.array([X0 + 17.0, Y0 + 16.0, 24.0])
OPK = np.radians([6.0, -10.0, 20.0])


def exact_rays(scene, cam: Camera, xyz, opk, pixels: np.ndarray) -> np.ndarray:
    """Unit chord directions (mapping frame) of pixels, per pixel, as core.simulation.render
    builds them at its lattice nodes."""
    dsm, zmin = scene.dsm, scene.tracer.zmin
    xc = dsm.grid.x0 + dsm.grid.cols * dsm.cell / 2
    yc = dsm.grid.y_top - dsm.grid.rows * dsm.cell / 2
    local = LocalFrame.at_map_point(MappingFrame(scene.crs), [xc, yc, zmin])
    c_loc, m_loc = eo_map_to_local(xyz[None], opk[None], local)
    d = cam.ray_from_ideal(cam.ideal_from_pixel(pixels)) @ m_loc[0]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    z_low = local.map_to_enu(np.array([[xc, yc, zmin - 10.0]]))[0, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(d[:, 2] < -1e-6, (c_loc[0, 2] - z_low) / -d[:, 2], 1e3)
    n = len(pixels)
    return chord_rays(local, np.repeat(xyz[None], n, 0), np.repeat(c_loc, n, 0), d,
                      np.maximum(s, 1.0))  # fmt: skip


def texture(scene, x: np.ndarray, y: np.ndarray, opt: RenderOptions) -> np.ndarray:
    """(N, 3) colour the renderer gives the ground points (x, y): class albedo x Lambert
    shading of the DSM face under them."""
    above = np.column_stack([x, y, np.full(x.size, 100.0)])
    down = intersect_dsm(scene.dsm, above, np.tile([0.0, 0.0, -1.0], (x.size, 1)),
                         min_incidence_deg=0.0)  # fmt: skip
    normal = np.column_stack([-down.gradient, np.ones(x.size)])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    sun = sun_vector(opt.sun_azimuth_deg, opt.sun_elevation_deg)
    return 255 * scene.albedo_at(x, y) * lambert(normal, sun, opt.ambient)[:, None]


def fisheye_case(projection: str) -> dict:
    """The rendered fisheye image, its orthophotos (plain and true) and the truths."""
    scene, dsm = _scene()
    cam = fisheye(projection)
    # direction lattice of 2 px: the renderer's interpolated rays within 0.003 px of the
    # exact ones over the scene (16 px, enough for a frame camera, gives 0.04-0.14 px here)
    opt = RenderOptions(step_px=1, noise_dn=0.0, direction_grid_px=2)
    img = render_image(scene, cam, XYZ, OPK, opt)
    proj = OrthoProjector.build(cam, XYZ, OPK, dsm, CRS)
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
    ok = np.isfinite(col)
    dirs = exact_rays(scene, cam, XYZ, OPK, np.column_stack([col[ok], row[ok]]))
    hits = intersect_dsm(scene.tracer, np.broadcast_to(XYZ, dirs.shape), dirs,
                         min_incidence_deg=0.0)  # fmt: skip
    land = np.full((grid.rows, grid.cols, 3), np.nan)
    land[ok] = hits.points
    ground = np.dstack([gx, gy, z])
    gap = np.linalg.norm(land - ground, axis=2)
    hidden = ok & (np.linalg.norm(land - XYZ, axis=2) < np.linalg.norm(ground - XYZ, axis=2)
                   - 0.05)  # fmt: skip
    truth = np.full((grid.rows, grid.cols, 3), np.nan)
    truth[ok] = texture(scene, gx[ok], gy[ok], opt)
    return {"cam": cam, "dsm": dsm, "proj": proj, "grid": grid, "plain": plain,
            "plain_valid": plain_valid, "true_valid": true_valid, "true": true_, "col": col,
            "row": row, "z": z, "gap": gap, "hidden": hidden, "truth": truth, "gx": gx,
            "gy": gy}  # fmt: skip


@pytest.fixture(scope="module", params=sorted(FOCAL))
def case(request):
    return fisheye_case(request.param)


def test_cells_land_on_their_ground_point(case):
    e = case
    ok = np.isfinite(e["col"])
    ground = (e["z"] < 3.0) & ok & ~e["hidden"]
    roof = (e["z"] > 7.9) & ok
    for region in (ground, roof):
        keep = _interior(region, 3)
        assert keep.sum() > 2000
        err = e["gap"][keep] / GSD  # cells
        rms = float(np.sqrt(np.mean(err**2)))
        assert rms < 0.02 and err.max() < 0.05, (e["cam"].projection, rms, err.max())


def _forward_check(
    proj: OrthoProjector, grid, col: np.ndarray, row: np.ndarray, z: np.ndarray
) -> int:
    """Assert the cells' pixels are collinearity per cell (every ground point brought into the
    ENU frame by pyproj one by one) within 2e-3 px and valid exactly where the forward model
    images them (a 0.01 px sliver along the image border aside); the count of valid cells."""
    cam = proj.camera
    xs = grid.x0 + (np.arange(grid.cols) + 0.5) * grid.cell
    ys = grid.y_top - (np.arange(grid.rows) + 0.5) * grid.cell
    gx, gy = np.meshgrid(xs, ys)
    pts = np.column_stack([gx.ravel(), gy.ravel(), z.ravel()])
    has_z = np.isfinite(pts[:, 2])
    enu = proj.local.map_to_enu(pts[has_z])
    eo = np.r_[proj.centre_local, matrix_to_opk(proj.m_local)]
    px, inside, converged = project_with_status(enu, eo, cam)
    got = np.column_stack([col.ravel(), row.ravel()])[has_z]
    seen = inside & converged & cam.in_frame(px)
    valid = np.isfinite(got[:, 0])
    border = cam.in_frame(px, -0.01) & ~cam.in_frame(px, 0.01)
    assert np.array_equal(valid[~border], seen[~border])
    err = np.linalg.norm(got[valid & seen] - px[valid & seen], axis=1)
    assert err.max() < 2e-3, (cam.projection, err.max())
    return int(valid.sum())


def test_cells_project_as_the_forward_model(case):
    """The orthophoto's lattices (a, b per cell, lens lattice) against collinearity per cell."""
    e = case
    proj = e["proj"]
    cam = proj.camera
    assert _forward_check(proj, e["grid"], e["col"], e["row"], e["z"]) > 50_000
    # the perspective formula with the same focal length: many pixels off
    flat = dataclasses.replace(cam, projection="perspective")
    p2 = OrthoProjector.build(flat, proj.xyz, proj.opk, e["dsm"], CRS)
    col2, row2, _ = p2.pixels(e["grid"], 0, 0, e["grid"].rows, e["grid"].cols)
    both = np.isfinite(col2) & np.isfinite(e["col"])
    off = np.hypot(col2 - e["col"], row2 - e["row"])[both]
    assert np.median(off) > 10.0, np.median(off)


def test_a_colmap_opencv_fisheye_camera_projects_as_the_forward_model():
    """An equidistant camera with OpenCV's forward fisheye lens (k1..k4, as importcolmap and
    importopensfm write OPENCV_FISHEYE cameras): the same check, no rendering needed."""
    _, dsm = _scene()
    cam = camera_from_dict({"name": "colmap", "focal_mm": 3.58, "pixel_size_mm": 0.01,
                            "width_px": 800, "height_px": 600, "projection": "equidistant",
                            "x0_mm": 0.05, "y0_mm": -0.03,
                            "distortion": {"model": "opencv_fisheye", "k1": 0.03, "k2": -0.01,
                                           "k3": 0.002, "k4": 0.0, "scale_mm": 3.58,
                                           "aspect": 1.0}})  # fmt: skip
    proj = OrthoProjector.build(cam, XYZ, OPK, dsm, CRS)
    grid = ortho_grid(proj.footprint(), 0.1)
    col, row, z = proj.pixels(grid, 0, 0, grid.rows, grid.cols)
    assert _forward_check(proj, grid, col, row, z) > 50_000


def _square(keep: np.ndarray) -> tuple[int, int, int]:
    """(row, col, size) of the first large square of cells all in ``keep``."""
    for size in (192, 128, 96):
        for rr in range(0, keep.shape[0] - size, 8):
            for cc in range(0, keep.shape[1] - size, 8):
                if keep[rr : rr + size, cc : cc + size].all():
                    return rr, cc, size
    raise AssertionError("no square of 96 cells in the region")


def test_texture_reproduced_without_shift(case):
    e = case
    gray = lambda a: a.astype(np.float64) @ np.array([0.299, 0.587, 0.114])  # noqa: E731
    ortho = gray(np.moveaxis(e["plain"], 0, 2))
    truth = gray(np.nan_to_num(e["truth"]))
    keep = _interior(e["plain_valid"] & (e["z"] < 3.0) & ~e["hidden"], 4)
    rr, cc, size = _square(keep)
    dx, dy, peak = phase_correlation(truth[rr : rr + size, cc : cc + size],
                                     ortho[rr : rr + size, cc : cc + size])  # fmt: skip
    assert math.hypot(dx, dy) < 0.05 and peak > 0.8, (e["cam"].projection, dx, dy, peak)


def test_true_ortho_flags_what_the_exact_rays_hide(case):
    import cv2

    e = case
    both = e["plain_valid"]
    occluded = both & ~e["true_valid"]
    hidden = e["hidden"] & both
    assert hidden.sum() > 1000
    k = np.ones((3, 3), np.uint8)
    border = cv2.dilate(hidden.astype(np.uint8), k) != cv2.erode(hidden.astype(np.uint8), k)
    sure = both & ~border
    assert np.array_equal(occluded[sure], hidden[sure])
    np.testing.assert_array_equal(e["true"][:, e["true_valid"]], e["plain"][:, e["true_valid"]])


def test_beyond_the_field_is_no_data_and_a_wide_fisheye_sees_past_90_degrees():
    """Tilted 75 degrees: ground 90-100 degrees off the axis is imaged by an equidistant lens
    (its field reaches 180 degrees), never by an orthographic one (90)."""
    _, dsm = _scene()
    opk = np.radians([0.0, 75.0, 0.0])  # the axis 15 degrees below the horizon
    xyz = np.array([X0 + 20.0, Y0 + 20.0, 30.0])
    theta_of = {}
    for projection in ("equidistant", "orthographic"):
        cam = Camera("wide", 2.0, 0.01, 800, 600, 0.0, 0.0, projection=projection)
        proj = OrthoProjector.build(cam, xyz, opk, dsm, CRS)
        grid = ortho_grid((X0, Y0, X0 + 40.0, Y0 + 40.0), 0.2)
        col, _, z = proj.pixels(grid, 0, 0, grid.rows, grid.cols)
        xs = grid.x0 + (np.arange(grid.cols) + 0.5) * grid.cell
        ys = grid.y_top - (np.arange(grid.rows) + 0.5) * grid.cell
        gx, gy = np.meshgrid(xs, ys)
        enu = proj.local.map_to_enu(np.column_stack([gx.ravel(), gy.ravel(), z.ravel()]))
        q = (enu - proj.centre_local) @ proj.m_local.T
        theta = np.degrees(np.arctan2(np.hypot(q[:, 0], q[:, 1]), -q[:, 2]))
        theta_of[projection] = theta[np.isfinite(col.ravel())]
    assert theta_of["equidistant"].max() > 95.0
    assert theta_of["orthographic"].max() < 90.0 and theta_of["orthographic"].size > 1000


def test_fisheye_block_through_the_orthorectify_and_orthomosaic_jobs(tmp_path):
    """Two equisolid fisheye images of the house from opposite sides, through the command
    line: true orthophotos, then their mosaic; the mosaic's ground is the renderer's texture
    (no shift) and ground hidden in one view is filled from the other."""
    import pyproj
    from lidarphoto.core.cli import main as cli_main
    from lidarphoto.core.io.camera import write_camera_json
    from lidarphoto.core.io.dsm import write_dsm
    from lidarphoto.core.io.orientation import write_eo_csv
    from lidarphoto.core.io.raster import RasterReader
    from lidarphoto.core.io.raster_write import write_rgb_tiff
    from lidarphoto.core.photo.orientation import ExteriorOrientationTable

    scene, dsm = _scene()
    cam = fisheye("equisolid")
    xyz = np.array([[X0 + 12.0, Y0 + 11.0, 24.0], [X0 + 28.0, Y0 + 29.0, 25.0]])
    opk = np.radians([[6.0, -10.0, 20.0], [-5.0, 8.0, 200.0]])
    eo = ExteriorOrientationTable(("sw", "ne"), np.array([0.0, 1.0]), ("a", "a"), xyz, opk,
                                  pyproj.CRS.from_user_input(CRS).to_wkt())  # fmt: skip
    opt = RenderOptions(step_px=1, noise_dn=0.0, direction_grid_px=2)
    for k, name in enumerate(eo.image_id):
        write_rgb_tiff(tmp_path / "images" / f"{name}.tif",
                       render_image(scene, cam, xyz[k], opk[k], opt).rgb)  # fmt: skip
    write_camera_json(tmp_path / "fisheye.json", cam)
    write_eo_csv(tmp_path / "eo.csv", eo)
    write_dsm(tmp_path / "dsm.tif", dsm)
    out = tmp_path / "orthos"
    assert cli_main(["orthorectify", "--camera", str(tmp_path / "fisheye.json"), "--eo",
                     str(tmp_path / "eo.csv"), "--images", str(tmp_path / "images"), "--dsm",
                     str(tmp_path / "dsm.tif"), "--crs", CRS, "--gsd", str(GSD),
                     "--true-ortho", "true", "--output-folder", str(out)]) == 0  # fmt: skip
    assert sorted(p.name for p in out.iterdir()) == ["ne_ortho.tif", "sw_ortho.tif"]
    mosaic = tmp_path / "m.tif"
    assert cli_main(["orthomosaic", "--orthophotos", str(out), "--output", str(mosaic)]) == 0
    with RasterReader(mosaic) as src:
        info, data, mask = src.info, src.read(), src.read_mask()
    have = []
    for name in ("sw", "ne"):
        with RasterReader(out / f"{name}_ortho.tif") as src:
            gt, m = src.info.geotransform, src.read_mask()
        c0 = round((gt[0] - info.geotransform[0]) / GSD)
        r0 = round((info.geotransform[3] - gt[3]) / GSD)
        full = np.zeros(mask.shape, bool)
        full[r0 : r0 + m.shape[0], c0 : c0 + m.shape[1]] = m
        have.append(full)
    assert np.array_equal(mask, have[0] | have[1])
    assert (have[1] & ~have[0]).sum() > 500 and (have[0] & ~have[1]).sum() > 500
    gt = info.geotransform
    xs = gt[0] + (np.arange(mask.shape[1]) + 0.5) * GSD
    ys = gt[3] - (np.arange(mask.shape[0]) + 0.5) * GSD
    gx, gy = np.meshgrid(xs, ys)
    z = dsm.height_at(gx.ravel(), gy.ravel()).reshape(gx.shape)
    keep = _interior(mask & (z < 3.0), 4)
    gray = np.array([0.299, 0.587, 0.114])
    truth = np.zeros(mask.shape)
    truth[keep] = texture(scene, gx[keep], gy[keep], opt) @ gray
    mos = np.moveaxis(data, 0, 2).astype(np.float64) @ gray
    rr, cc, size = _square(keep)
    dx, dy, peak = phase_correlation(truth[rr : rr + size, cc : cc + size],
                                     mos[rr : rr + size, cc : cc + size])  # fmt: skip
    assert math.hypot(dx, dy) < 0.05 and peak > 0.8, (dx, dy, peak)
