"""Monoplotting against truth: a simulated camera over the DSM of a real AHN3 tile, image points
projected rigorously (ENU frame, lens distortion) from points ON the triangulated surface; the
plain DDA, a brute-force dense sampling of the ray and Makarovic's iteration as references;
the propagated covariance against Monte Carlo scatter; per-point statuses for bad input."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.errors import CrsError
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import image_rays, project
from lidarphoto.core.geometry.distortion import distortion_from_dict
from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
from lidarphoto.core.geometry.grid import Grid
from lidarphoto.core.geometry.planes import fit_plane
from lidarphoto.core.geometry.raycast import (
    DsmTracer,
    dal_poz_intersect,
    dal_poz_plane,
    intersect_dsm,
)
from lidarphoto.core.geometry.rotations import matrix_to_opk
from lidarphoto.core.geometry.surface import Dsm
from lidarphoto.core.io.dsm import dsm_from_las
from lidarphoto.core.io.monoplot import write_monoplot_lines_csv, write_monoplot_points_csv
from lidarphoto.core.io.planes import read_planes_csv, write_planes_csv
from lidarphoto.core.photo.monoplot import (
    STATUS_TEXT,
    intersect_planes,
    makarovic,
    monoplot,
    propagate_covariance,
)
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.photo.orientation import ExteriorOrientationTable, eo_map_to_local

AHN3 = Path(__file__).resolve().parents[1] / "data" / "ahn3" / "ahn3_delft_crop60.laz"
CRS = "EPSG:28992"


def run_monoplot(obs, camera, table, dsm, crs, planes=None, output_csv=None, lines_csv=None,
                 **options):  # fmt: skip
    """Monoplot with the plane table read from a file and the tables written, as the job."""
    res = monoplot(obs, camera, table, dsm, crs, planes=read_planes_csv(planes) if planes else (),
                   **options)  # fmt: skip
    if output_csv:
        write_monoplot_points_csv(output_csv, res)
    if lines_csv:
        write_monoplot_lines_csv(lines_csv, res)
    return res
CAMERA = Camera(
    "sim", focal_mm=35.0, pixel_size_mm=0.005, width_px=4000, height_px=3000,
    x0_mm=0.02, y0_mm=-0.01, distortion=distortion_from_dict({"model": "brown_conrady",
                                                              "k1": -2e-5, "p1": 1e-6}),
)  # fmt: skip


@pytest.fixture(scope="module")
def dsm() -> Dsm:
    return dsm_from_las(AHN3, 0.5, crs=CRS)


def _eo_table(dsm: Dsm, height: float = 140.0) -> ExteriorOrientationTable:
    g = dsm.grid
    centre = np.array([[g.x0 + 0.5 * g.cols * g.cell + 9.0, g.y_top - 0.5 * g.rows * g.cell - 7.0,
                        height]])  # fmt: skip
    opk = np.radians([[2.0, -3.0, 25.0]])
    return ExteriorOrientationTable(("img1",), np.array([np.nan]), ("",), centre, opk, CRS)


def _project_rigorous(points: np.ndarray, table: ExteriorOrientationTable) -> np.ndarray:
    """Truth pixels: map -> ENU, camera pose in ENU, collinearity with the lens model."""
    local = LocalFrame.at_map_point(MappingFrame.from_user_input(CRS), points.mean(axis=0))
    c, m = eo_map_to_local(table.xyz, table.opk, local)
    eo = np.r_[c[0], matrix_to_opk(m[0])]
    return project(local.map_to_enu(points), eo, CAMERA)


def _surface_points(dsm: Dsm, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    xc, yc = dsm.centre_origin
    rows, cols = dsm.heights.shape
    x = xc + rng.uniform(0.5, cols - 1.5, n) * dsm.cell
    y = yc - rng.uniform(0.5, rows - 1.5, n) * dsm.cell
    return np.column_stack([x, y, dsm.height_at(x, y)])


def _clearance(dsm: Dsm, centre: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Minimum height of the straight segment camera -> point above the surface (sampled
    every ~2 cm), ignoring the last centimetre (where it meets the surface)."""
    s = np.linspace(0.0, 1.0, 8000)[None, :, None]
    seg = centre + s * (points - centre)[:, None, :]
    length = np.linalg.norm(points - centre, axis=1)[:, None]
    gap = seg[..., 2] - dsm.height_at(seg[..., 0].ravel(), seg[..., 1].ravel()).reshape(
        seg.shape[:2]
    )
    gap[(1 - s[..., 0]) * length < 0.01] = np.inf
    return np.nanmin(gap, axis=1)


def _observations(pixels: np.ndarray, image: str = "img1") -> ImageObservations:
    n = len(pixels)
    return ImageObservations.from_arrays(
        [image] * n, [f"p{k}" for k in range(n)], pixels, np.full(n, 0.5), ["check"] * n, [""] * n
    )


def _brute_force(dsm: Dsm, o: np.ndarray, d: np.ndarray, step_cells: float = 0.01) -> np.ndarray:
    """Dense sampling along each ray (every 1/100 cell), first sample below the surface, then
    bisection: the hit points (NaN for none)."""
    zmin, zmax = dsm.z_range
    t0 = (zmax + 1e-3 - o[:, 2]) / d[:, 2]
    t1 = (zmin - 1e-3 - o[:, 2]) / d[:, 2]
    dt = step_cells * dsm.cell / np.hypot(d[:, 0], d[:, 1])
    m = int(np.ceil(((t1 - t0) / dt).max())) + 2
    t = t0[:, None] + dt[:, None] * np.arange(m)[None, :]
    p = o[:, None, :] + t[..., None] * d[:, None, :]
    below = p[..., 2] <= dsm.height_at(p[..., 0].ravel(), p[..., 1].ravel()).reshape(t.shape)
    k = np.argmax(below, axis=1)
    found = below[np.arange(len(o)), k] & (k > 0)
    lo, hi = t[np.arange(len(o)), np.maximum(k - 1, 0)], t[np.arange(len(o)), k]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        q = o + mid[:, None] * d
        under = q[:, 2] <= dsm.height_at(q[:, 0], q[:, 1])
        hi, lo = np.where(under, mid, hi), np.where(under, lo, mid)
    out = o + hi[:, None] * d
    out[~found] = np.nan
    return out


# --------------------------------------------------------------------------- Eqs. 6-10
def test_dal_poz_determinant_form_is_the_face_plane():
    rng = np.random.default_rng(1)
    o, p, q = rng.normal(size=(3, 50, 3)) * 10
    a, b = dal_poz_plane(o, p, q)
    for v in (o, p, q):
        np.testing.assert_allclose(np.einsum("ij,ij->i", a, v) + b, 0, atol=1e-9)
    # Eq. 6 itself: det[G - O; P - O; Q - P] = 0 at the intersection
    c, n = rng.normal(size=(50, 3)) * 30, rng.normal(size=(50, 3))
    g, t = dal_poz_intersect(c, n, a, b)
    dets = np.linalg.det(np.stack([g - o, p - o, q - p], axis=1))
    np.testing.assert_allclose(dets, 0, atol=1e-6 * np.abs(np.linalg.det(np.stack(
        [c - o, p - o, q - p], axis=1))).max())  # fmt: skip
    np.testing.assert_allclose(g, c + t[:, None] * n)


# --------------------------------------------------------------------------- ray casting
def test_traversal_agrees_with_plain_dda_and_brute_force(dsm):
    rng = np.random.default_rng(7)
    n = 2000
    targets = _surface_points(dsm, n, 3)
    targets[:, :2] += rng.normal(0, 3, (n, 2))  # some rays leave the tile
    centre = np.array([targets[:, 0].mean() - 20, targets[:, 1].mean() + 10, 80.0])
    o = np.repeat(centre[None], n, axis=0)
    d = targets - centre
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    fast = intersect_dsm(dsm, o, d, chunk_size=397)  # several chunks and pools
    plain = intersect_dsm(dsm, o, d, accelerate=False)
    np.testing.assert_array_equal(fast.status, plain.status)
    np.testing.assert_allclose(fast.points, plain.points, atol=1e-9)
    hit = np.isin(fast.status, (0, 1))
    assert 0.6 < hit.mean() < 1.0 and (fast.status == 2).any()
    assert set(np.unique(fast.status)) <= {0, 1, 2}  # every ray ends: hit or outside
    np.testing.assert_allclose(fast.points[hit, 2], dsm.height_at(*fast.points[hit, :2].T),
                               atol=1e-6)  # fmt: skip
    ref = _brute_force(dsm, o, d)
    np.testing.assert_array_equal(np.isfinite(ref[:, 0]), hit)
    err = np.linalg.norm(ref[hit] - fast.points[hit], axis=1)
    # dense sampling can step over a sliver thinner than 1/100 cell and find a later hit
    later = np.einsum("ij,ij->i", ref[hit] - fast.points[hit], d[hit]) > 0
    assert np.mean(err < 1e-6) > 0.99 and np.all((err < 1e-6) | later)


def test_camera_over_ahn3_recovers_surface_points_below_a_millimetre(dsm):
    table = _eo_table(dsm)
    truth = _surface_points(dsm, 600, 11)
    pixels = _project_rigorous(truth, table)
    inside = CAMERA.in_frame(pixels)
    truth, pixels = truth[inside], pixels[inside]
    res = run_monoplot(_observations(pixels), CAMERA, table, dsm, CRS)
    clear = _clearance(dsm, table.xyz[0], truth)
    visible, occluded = clear > 2e-3, clear < -2e-3
    assert visible.sum() > 300 and occluded.sum() > 10
    ok = res.status[visible] == 0
    err = np.linalg.norm(res.points[visible] - truth[visible], axis=1)
    assert ok.mean() > 0.97  # the rest: grazing hits on walls
    assert np.all(err < 1e-3), err.max()
    # occluded points: the visible (occluding) surface, closer to the camera
    occ = res.points[occluded]
    assert np.isin(res.status[occluded], (0, 1)).all()
    np.testing.assert_allclose(occ[:, 2], dsm.height_at(occ[:, 0], occ[:, 1]), atol=1e-6)
    closer = np.linalg.norm(truth[occluded] - table.xyz[0], axis=1) - np.linalg.norm(
        occ - table.xyz[0], axis=1
    )
    assert (closer > 0.01).all()
    # the same with Makarovic's iteration where it converges (not on walls, not occluded)
    mk = run_monoplot(_observations(pixels), CAMERA, table, dsm, CRS, method="makarovic")
    conv = visible & (mk.status == 0)
    assert conv.sum() > 0.8 * visible.sum()
    agree = np.linalg.norm(mk.points[conv] - res.points[conv], axis=1) < 1e-3
    assert agree.mean() > 0.95


def test_makarovic_iteration_agrees_where_it_converges(dsm):
    truth = _surface_points(dsm, 300, 5)
    centre = truth.mean(axis=0) + [5.0, -5.0, 200.0]
    d = truth - centre
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = np.repeat(centre[None], len(d), axis=0)
    direct = intersect_dsm(dsm, o, d)
    pts, status, iters = makarovic(dsm, o, d, tol=1e-6)
    both = (status == 0) & (direct.status == 0)
    assert both.mean() > 0.8 and iters[both].max() < 100
    same = np.linalg.norm(pts[both] - direct.points[both], axis=1) < 1e-3
    assert same.mean() > 0.95
    # where they differ, Makarovic stopped on another crossing of the ray with the surface,
    # further from the camera: the first (visible) one is the direct method's
    other = np.flatnonzero(both)[~same]
    np.testing.assert_allclose(pts[other, 2], dsm.height_at(*pts[other, :2].T), atol=1e-5)
    farther = np.linalg.norm(pts[other] - o[other], axis=1) - direct.t[other]
    assert np.all(farther > 0)


def test_plane_intersection_and_planes_file(tmp_path, dsm):
    rng = np.random.default_rng(4)
    table = _eo_table(dsm)
    g = dsm.grid
    xy = np.column_stack([rng.uniform(g.x0 + 10, g.x0 + 50, 200),
                          rng.uniform(g.y_top - 50, g.y_top - 10, 200)])  # fmt: skip
    z = 12.0 + 0.3 * (xy[:, 0] - g.x0) - 0.2 * (xy[:, 1] - g.y_top)
    pts = np.column_stack([xy, z + rng.normal(0, 0.02, 200)])
    plane = fit_plane(pts, plane_id=3)
    write_planes_csv(tmp_path / "planes.csv", [plane])
    truth = np.column_stack([xy[:20], z[:20]])
    truth[:, 2] -= (plane.normal @ truth.T + plane.d) / plane.normal[2]  # onto the fitted plane
    pixels = _project_rigorous(truth, table)
    obs = ImageObservations.from_arrays(
        ["img1"] * 21, [f"r{k}" for k in range(21)], np.vstack([pixels, pixels[:1]]),
        np.full(21, 0.3), ["tie"] * 21, ["3"] * 20 + ["99"],
    )  # fmt: skip
    res = run_monoplot(obs, CAMERA, table, dsm, CRS, planes=tmp_path / "planes.csv")
    assert [STATUS_TEXT[int(s)] for s in res.status[-1:]] == ["unknown_plane"]
    np.testing.assert_array_less(np.linalg.norm(res.points[:20] - truth, axis=1), 1e-3)
    assert {r[6] for r in res.rows[:20]} == {"plane"}
    s = res.sigmas[:20]
    assert np.all(s > 0) and np.all(s < 0.5)
    # a ray parallel to the plane or pointing away from it
    _, st = intersect_planes([[0, 0, 10.0], [0, 0, 10]], [[1.0, 0, 0], [0, 0, 1]],
                             [[0, 0, 1.0], [0, 0, 1]], [0.0, 0.0])  # fmt: skip
    assert [STATUS_TEXT[int(v)] for v in st] == ["parallel", "parallel"]


# --------------------------------------------------------------------------- precision
def test_propagated_covariance_matches_monte_carlo():
    rng = np.random.default_rng(2025)
    rows, cols, cell = 120, 120, 0.5
    grid = Grid(1000.0, 2060.0, cell, rows, cols)
    yy, xx = np.mgrid[0:rows, 0:cols] * cell
    base = (20.0 + 0.25 * xx - 0.15 * yy).astype(np.float32)
    dsm = Dsm(base, grid)
    cam = Camera("mc", focal_mm=50.0, pixel_size_mm=0.005, width_px=3000, height_px=3000)
    eo = np.array([1030.0, 2030.0, 180.0, *np.radians([1.5, -2.0, 40.0])])
    xc, yc = dsm.centre_origin
    truth_xy = np.column_stack([xc + rng.uniform(8, 50, 30), yc - rng.uniform(8, 50, 30)])
    truth = np.column_stack([truth_xy, dsm.height_at(*truth_xy.T)])
    pix = project(truth, eo, cam)
    s_px, s_h = 0.5, 0.05
    s_eo = np.array([0.05, 0.05, 0.08, *np.radians([0.005, 0.005, 0.008])])
    o, d = image_rays(pix, eo, cam)
    hits = intersect_dsm(dsm, o, d)
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
    # chi-square with 3 degrees of freedom per point: mean 3; the EO noise is shared by the
    # 30 points of a draw, so the effective sample is ~300, sd of the mean ~ sqrt(6/300)
    assert abs(d2.mean() - 3.0) < 0.4, d2.mean()
    ratio = errs.var(axis=0) / np.diagonal(cov, axis1=1, axis2=2)
    assert 0.75 < np.median(ratio) < 1.25
    # each point: its own chi-square over the draws (mean of 300 values, sd ~0.14)
    assert np.mean(np.abs(d2.mean(axis=0) - 3) < 0.6) > 0.9


# --------------------------------------------------------------------------- bad input
def test_bad_input_gives_statuses_not_crashes(tmp_path, dsm):
    table = _eo_table(dsm)
    truth = _surface_points(dsm, 40, 9)
    pixels = _project_rigorous(truth, table)
    corner = np.array([[5.0, 5.0]])  # an image corner: the ray leaves the 60 m tile
    obs = ImageObservations.from_arrays(
        ["img1"] * 41 + ["img_without_eo"], [f"p{k}" for k in range(42)],
        np.vstack([pixels, corner, pixels[:1]]), np.full(42, 0.5), ["check"] * 42, [""] * 42,
    )  # fmt: skip
    out = tmp_path / "points.csv"
    res = run_monoplot(obs, CAMERA, table, dsm, CRS, output_csv=out)
    text = [STATUS_TEXT[int(s)] for s in res.status]
    assert text[40] == "outside" and text[41] == "no_orientation"
    assert np.isnan(res.points[40:]).all() and np.isnan(res.covariance[40:]).all()
    with open(out, encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["status_text"] for r in rows[40:]] == ["outside", "no_orientation"]
    assert rows[40]["X"] == "" and float(rows[0]["sigma_z"]) > 0
    # the DSM in its own CRS (RD New + NAP) while the EO is in RD New and PROJ lacks the NAP
    # geoid: refused (docs/conventions.md), never heights of two datums mixed
    other = dsm_from_las(AHN3, 0.5)
    with pytest.raises(CrsError, match=r"RD New \+ NAP height' cannot be brought into .*"
                       r"nl_nsgi_nlgeo2018"):
        run_monoplot(obs, CAMERA, table, other, CRS, output_csv=tmp_path / "refused.csv")
    assert not (tmp_path / "refused.csv").exists()
    # a nodata hole under the points: the rays that cross it are reported
    holes = dsm.heights.copy()
    holes[40:80, 40:80] = np.nan
    res = run_monoplot(obs, CAMERA, table, Dsm(holes, dsm.grid, dsm.crs), CRS)
    u, v = dsm.to_grid_uv(truth[:, 0], truth[:, 1])
    in_hole = (u > 39) & (u < 80) & (v > 39) & (v < 80)
    assert in_hole.sum() >= 2
    assert np.all((res.status[:40][in_hole] == 3) | np.isfinite(res.points[:40][in_hole, 0]))
    assert (res.status[:40][in_hole] == 3).sum() >= 2
    hu, hv = dsm.to_grid_uv(*res.points[np.isfinite(res.points[:, 0]), :2].T)
    assert not np.any((hu > 40) & (hu < 79) & (hv > 40) & (hv < 79))
    # an upward ray never reaches the DSM
    up = intersect_dsm(dsm, [[0, 0, 100.0]], [[0, 0, 1.0]])
    assert STATUS_TEXT[int(up.status[0])] == "outside"


def test_lines_and_densified_lines(tmp_path, dsm):
    table = _eo_table(dsm)
    truth = _surface_points(dsm, 3, 21)
    pixels = _project_rigorous(truth, table)
    obs = ImageObservations.from_arrays(
        ["img1"] * 4, ["a", "b", "c", "q"], np.vstack([pixels, [[2000.0, 1500.0]]]),
        np.full(4, 0.5), ["line", "line", "line", "check"], ["7", "7", "7", ""],
    )  # fmt: skip
    res = run_monoplot(obs, CAMERA, table, dsm, CRS, line_step_px=25.0,
                       lines_csv=tmp_path / "lines.csv")  # fmt: skip
    assert len(res.lines) == 1
    line = res.lines[0]
    seg = np.linalg.norm(np.diff(pixels, axis=0), axis=1)
    assert len(line.vertices) == 3 + int(np.sum(np.ceil(seg / 25.0) - 1))
    v = line.vertices[np.isfinite(line.vertices).all(axis=1)]
    assert len(v) >= 0.9 * len(line.vertices)
    np.testing.assert_allclose(v[:, 2], dsm.height_at(v[:, 0], v[:, 1]), atol=1e-6)
    with open(tmp_path / "lines.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert rows[0]["wkt"].startswith("LINESTRING Z") and int(rows[0]["n_vertices"]) == len(
        line.vertices
    )
    assert [r[0:3] for r in res.rows[:1]] == [("img1", "q", "check")]


# --------------------------------------------------------------------------- DSM in another CRS
def _utm_dsm(rows: int = 160, cols: int = 150, cell: float = 0.5) -> tuple[Dsm, callable]:
    """A smooth surface (WGS 84 ellipsoidal heights) on a UTM 31N grid near Delft, and its
    analytic height function (curvature <= 1.1e-3 /m: the triangulation is exact to 0.1 mm)."""
    x0, y_top = 594000.0, 5763000.0

    def f(x, y):
        return 45.0 + 0.02 * (x - x0) + 1.5 * np.sin((y - y_top) / 40.0)

    xc = x0 + (np.arange(cols) + 0.5) * cell
    yc = y_top - (np.arange(rows) + 0.5) * cell
    z = f(xc[None, :], yc[:, None]).astype(np.float32)
    return Dsm(z, Grid(x0, y_top, cell, rows, cols), MappingFrame.from_user_input(
        "EPSG:32631").crs), f  # fmt: skip


def test_dsm_in_another_crs_is_resampled_and_heights_transformed():
    import pyproj
    from lidarphoto.core.geometry.surface import reproject_dsm

    utm, f = _utm_dsm()
    rd = reproject_dsm(utm, CRS)
    assert rd.crs.to_epsg() == 28992 and abs(rd.cell - 0.5) < 0.01  # RD's scale here ~1.0001
    # independent check through pyproj alone, at the centres of the target cells
    to_utm = pyproj.Transformer.from_crs("EPSG:28992", "EPSG:32631", always_xy=True)
    to_rd3 = pyproj.Transformer.from_crs(pyproj.CRS("EPSG:32631").to_3d(),
                                         pyproj.CRS("EPSG:28992").to_3d(), always_xy=True)
    g = rd.grid
    r, c = np.mgrid[0 : g.rows : 7, 0 : g.cols : 7]
    x, y = g.x0 + (c.ravel() + 0.5) * g.cell, g.y_top - (r.ravel() + 0.5) * g.cell
    ux, uy = to_utm.transform(x, y)
    _, _, h_rd = to_rd3.transform(ux, uy, f(ux, uy))
    got = rd.heights[r.ravel(), c.ravel()]
    inside = np.isfinite(got)
    assert inside.mean() > 0.8  # the rotated footprint leaves empty corners
    # Bessel (RD) vs WGS 84 ellipsoidal heights differ by ~43 m here: transformed, not copied
    assert np.all(np.abs(h_rd[inside] - f(ux, uy)[inside]) > 30)
    np.testing.assert_allclose(got[inside], h_rd[inside], atol=2e-4)


def test_monoplot_on_a_dsm_in_another_crs_reaches_the_truth():
    import pyproj

    utm, f = _utm_dsm()
    to_rd3 = pyproj.Transformer.from_crs(pyproj.CRS("EPSG:32631").to_3d(),
                                         pyproj.CRS("EPSG:28992").to_3d(), always_xy=True)
    # truth: surface points in RD New (ellipsoidal heights on Bessel)
    rng = np.random.default_rng(4)
    ux = utm.grid.x0 + rng.uniform(15, 60, 60)
    uy = utm.grid.y_top - rng.uniform(15, 65, 60)
    truth = np.column_stack(to_rd3.transform(ux, uy, f(ux, uy)))
    centre = truth.mean(axis=0) + [5.0, -3.0, 120.0]
    table = ExteriorOrientationTable(("img1",), np.array([np.nan]), ("",), centre[None],
                                     np.radians([[1.0, -2.0, 10.0]]), CRS)  # fmt: skip
    pixels = _project_rigorous(truth, table)
    res = run_monoplot(_observations(pixels), CAMERA, table, utm, CRS)
    assert {STATUS_TEXT[int(s)] for s in res.status} == {"ok"}
    # two triangulations of a surface with curvature 1.1e-3 /m at 0.5 m: ~0.1 mm in height
    assert np.abs(res.points - truth).max() < 1e-3
    assert res.dsm.crs.to_epsg() == 28992


def test_reprojecting_a_dsm_without_crs_is_refused():
    from lidarphoto.core.errors import CrsError
    from lidarphoto.core.geometry.surface import reproject_dsm

    utm, _ = _utm_dsm(rows=4, cols=4)
    bare = Dsm(utm.heights, utm.grid, None, "bare.tif")
    with pytest.raises(CrsError, match=r"bare\.tif.*no CRS"):
        reproject_dsm(bare, CRS)
