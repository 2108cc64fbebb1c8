"""Monoplotting with fisheye cameras against truth: a fisheye of each projection (equidistant,
equisolid, orthographic, stereographic, with a Brown lens) flown low and tilted over the DSM of
the real AHN3 tile, so that surface points lie up to 60 degrees off the optical axis; their
pixels from the forward model (rigorous ENU collinearity with the projection and the lens,
core.geometry.collinearity.project), monoplotted back. Noise-free: every visible point must
come back within 1e-3 of its pixel's footprint on the ground, where the perspective formula
with the same focal length misses by many footprints."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import image_rays, project
from lidarphoto.core.geometry.distortion import distortion_from_dict
from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
from lidarphoto.core.geometry.grid import Grid
from lidarphoto.core.geometry.projection import radius_derivative, radius_factor
from lidarphoto.core.geometry.raycast import DsmTracer, intersect_dsm
from lidarphoto.core.geometry.rotations import matrix_to_opk, opk_to_matrix
from lidarphoto.core.geometry.surface import Dsm
from lidarphoto.core.photo.monoplot import STATUS_TEXT, monoplot, propagate_covariance
from lidarphoto.core.photo.orientation import ExteriorOrientationTable, eo_map_to_local
from test_monoplot import CRS, _clearance, _observations, _surface_points, dsm  # noqa: F401

FISHEYES = ("equidistant", "equisolid", "orthographic", "stereographic")


def _camera(projection: str) -> Camera:
    """2000 x 1500 px of 3 um, f 2 mm (half diagonal 3.75 mm: beyond the orthographic field
    r = f in the corners), principal point off the centre, Brown k1 k2."""
    lens = distortion_from_dict({"model": "brown_conrady", "k1": 2e-3, "k2": -1e-4})
    return Camera("fish", 2.0, 0.003, 2000, 1500, 0.03, -0.02, lens, projection)


def _table(surface) -> ExteriorOrientationTable:
    g = surface.grid
    centre = np.array([[g.x0 + 0.5 * g.cols * g.cell + 4.0, g.y_top - 0.5 * g.rows * g.cell - 3.0,
                        32.0]])  # fmt: skip
    opk = np.radians([[8.0, -6.0, 25.0]])
    return ExteriorOrientationTable(("img1",), np.array([np.nan]), ("",), centre, opk, CRS)


def _truth_pixels(points, table, cam):
    """Pixels of the forward model, and each point's footprint: its range times the smaller
    angle a pixel subtends there (radially ps / (f g'), tangentially ps sin(theta) / (f g))."""
    local = LocalFrame.at_map_point(MappingFrame.from_user_input(CRS), points.mean(axis=0))
    c, m = eo_map_to_local(table.xyz, table.opk, local)
    enu = local.map_to_enu(points)
    px = project(enu, np.r_[c[0], matrix_to_opk(m[0])], cam)
    q = (enu - c[0]) @ opk_to_matrix(*matrix_to_opk(m[0])).T
    rng = np.linalg.norm(q, axis=1)
    theta = np.arctan2(np.hypot(q[:, 0], q[:, 1]), -q[:, 2])
    radial = 1.0 / radius_derivative(theta, cam.projection)
    with np.errstate(invalid="ignore", divide="ignore"):
        tangential = np.where(theta > 1e-9, np.sin(theta) / radius_factor(theta, cam.projection),
                              1.0)  # fmt: skip
    foot = rng * cam.pixel_size_mm / cam.focal_mm * np.minimum(radial, tangential)
    return px, foot, theta


@pytest.mark.parametrize("projection", FISHEYES)
def test_fisheye_monoplot_recovers_surface_points(dsm, projection):  # noqa: F811
    cam = _camera(projection)
    table = _table(dsm)
    truth = _surface_points(dsm, 800, 17)
    pixels, foot, theta = _truth_pixels(truth, table, cam)
    inside = np.isfinite(pixels).all(axis=1) & cam.in_frame(pixels)
    truth, pixels, foot, theta = truth[inside], pixels[inside], foot[inside], theta[inside]
    visible = _clearance(dsm, table.xyz[0], truth) > 2e-3
    assert visible.sum() > 300 and np.degrees(theta[visible]).max() > 60.0
    res = monoplot(_observations(pixels), cam, table, dsm, CRS)
    ok = visible & (res.status == 0)
    assert ok.sum() > 0.9 * visible.sum()  # the rest: grazing hits on walls
    rel = np.linalg.norm(res.points[ok] - truth[ok], axis=1) / foot[ok]
    assert rel.max() < 1e-3, (projection, rel.max(), np.median(rel))
    # the perspective formula with the same camera puts the points many footprints away
    flat = monoplot(_observations(pixels), dataclasses.replace(cam, projection="perspective"),
                    table, dsm, CRS)  # fmt: skip
    miss = np.linalg.norm(flat.points[ok] - truth[ok], axis=1) / foot[ok]
    assert np.nanmedian(miss) > 10.0, (projection, np.nanmedian(miss))


def test_pixel_beyond_the_orthographic_field_is_reported(dsm):  # noqa: F811
    cam = _camera("orthographic")
    table = _table(dsm)
    # image corners: the ideal radius (about 3.9 mm) exceeds f = 2 mm
    corners = np.array([[1.0, 1.0], [1999.0, 1499.0]])
    centre = np.array([cam.principal_point_px])
    res = monoplot(_observations(np.vstack([corners, centre])), cam, table, dsm, CRS)
    assert [STATUS_TEXT[int(s)] for s in res.status] == ["out_of_field"] * 2 + ["ok"]
    assert np.isnan(res.points[:2]).all() and np.isnan(res.covariance[:2]).all()
    assert np.isfinite(res.covariance[2]).all()


def test_monoplot_job_takes_a_fisheye_camera_file(tmp_path, dsm):  # noqa: F811
    """The ``monoplot`` algorithm with a fisheye camera JSON (as calibratecamera writes it):
    the point table carries the truth."""
    import csv

    from lidarphoto.core.io.camera import write_camera_json
    from lidarphoto.core.io.dsm import write_dsm
    from lidarphoto.core.io.observations import write_observations_csv
    from lidarphoto.core.io.orientation import write_eo_csv
    from lidarphoto.core.jobs import monoplot as monoplot_job
    from lidarphoto.core.jobs.runner import run_job

    cam = _camera("equisolid")
    table = _table(dsm)
    truth = _surface_points(dsm, 200, 23)
    pixels, foot, _ = _truth_pixels(truth, table, cam)
    keep = np.isfinite(pixels).all(axis=1) & cam.in_frame(pixels)
    keep &= _clearance(dsm, table.xyz[0], truth) > 2e-3
    truth, pixels, foot = truth[keep], pixels[keep], foot[keep]
    write_camera_json(tmp_path / "fisheye.json", cam)
    write_eo_csv(tmp_path / "eo.csv", table)
    write_dsm(tmp_path / "dsm.tif", dsm)
    write_observations_csv(tmp_path / "obs.csv", _observations(pixels))
    v = {"OBSERVATIONS": str(tmp_path / "obs.csv"), "CAMERA": str(tmp_path / "fisheye.json"),
         "EO": str(tmp_path / "eo.csv"), "DSM": str(tmp_path / "dsm.tif"), "CRS": CRS,
         "OUTPUT_CSV": str(tmp_path / "points.csv")}  # fmt: skip
    run_job(monoplot_job, v)
    with open(tmp_path / "points.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == len(truth) > 100
    ok = np.array([r["status_text"] == "ok" for r in rows])
    assert ok.mean() > 0.9
    got = np.array([[float(r[k]) for k in "XYZ"] for r in np.array(rows)[ok]])
    rel = np.linalg.norm(got - truth[ok], axis=1) / foot[ok]
    assert rel.max() < 1e-3, rel.max()


@pytest.mark.parametrize("projection", FISHEYES)
def test_fisheye_covariance_matches_monte_carlo(projection):
    """The propagated 3 x 3 covariance (the projection's own Jacobian) against the scatter of
    300 noisy draws (pixels, EO, DSM heights) for points 20-60 degrees off the axis, as
    tests/core/test_monoplot.py does for a perspective camera."""
    rng = np.random.default_rng(34)
    rows, cols, cell = 240, 240, 0.5
    grid = Grid(1000.0, 2120.0, cell, rows, cols)
    yy, xx = np.mgrid[0:rows, 0:cols] * cell
    base = (20.0 + 0.15 * xx - 0.1 * yy).astype(np.float32)
    surface = Dsm(base, grid)
    cam = _camera(projection)
    xc, yc = surface.centre_origin
    eo = np.array([xc + 60.0, yc - 60.0, 60.0, *np.radians([4.0, -3.0, 30.0])])
    off = np.radians(rng.uniform(20.0, 60.0, 30))
    az = rng.uniform(0.0, 2 * np.pi, 30)
    rad = (eo[2] - 38.0) * np.tan(off)
    truth_xy = np.column_stack([eo[0] + rad * np.cos(az), eo[1] + rad * np.sin(az)])
    truth = np.column_stack([truth_xy, surface.height_at(*truth_xy.T)])
    pix = project(truth, eo, cam)
    assert cam.in_frame(pix).all()
    s_px, s_h = 0.5, 0.05
    s_eo = np.array([0.03, 0.03, 0.05, *np.radians([0.01, 0.01, 0.015])])
    o, d = image_rays(pix, eo, cam)
    hits = intersect_dsm(surface, o, d)
    grad = np.column_stack([-hits.gradient, np.ones(30)])
    cov = propagate_covariance(truth, eo, cam, np.full(30, s_px), np.diag(s_eo**2), grad,
                               s_h**2 * np.sum(hits.weights**2, axis=1))  # fmt: skip
    draws = 300
    errs = np.empty((draws, 30, 3))
    for k in range(draws):
        noisy = Dsm((base + rng.normal(0, s_h, base.shape)).astype(np.float32), grid)
        o, d = image_rays(pix + rng.normal(0, s_px, pix.shape), eo + rng.normal(0, s_eo), cam)
        errs[k] = intersect_dsm(DsmTracer.build(noisy), o, d).points - truth
    d2 = np.einsum("kni,nij,knj->kn", errs, np.linalg.inv(cov), errs)
    # chi-square with 3 degrees of freedom: mean 3 (the EO noise is shared by a draw's 30
    # points: an effective sample of about 300, sd of the mean about sqrt(6 / 300) = 0.14)
    assert abs(d2.mean() - 3.0) < 0.4, (projection, d2.mean())
    ratio = errs.var(axis=0) / np.diagonal(cov, axis1=1, axis2=2)
    assert 0.75 < np.median(ratio) < 1.25, (projection, np.median(ratio))
