"""The orthorectify and orthomosaic jobs: files in, files out, through the command line and
run_job, on images rendered from a textured DSM (tests/core/test_orthophoto.py's scene) from
two sides of a house; bad inputs refused before anything is written."""

from __future__ import annotations

import csv
import logging
import math
from pathlib import Path

import cv2
import numpy as np
import pyproj
import pytest
from lidarphoto.core.cli import main as cli_main
from lidarphoto.core.errors import Cancelled, CrsError, InputError
from lidarphoto.core.geometry.camera import camera_from_dict
from lidarphoto.core.geometry.frames import transformer_3d
from lidarphoto.core.geometry.grid import Grid
from lidarphoto.core.geometry.surface import Dsm, reproject_dsm
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.dsm import write_dsm
from lidarphoto.core.io.orientation import write_eo_csv
from lidarphoto.core.io.raster import RasterReader, overview_factors
from lidarphoto.core.io.raster_write import GeoTiffWriter, write_rgb_tiff
from lidarphoto.core.jobs import orthomosaic, orthorectify
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.mosaic import MosaicOptions, MosaicSource, mosaic_grid, mosaic_tiles
from lidarphoto.core.photo.orientation import ExteriorOrientationTable
from lidarphoto.core.quality.registration import phase_correlation
from lidarphoto.core.simulation.render import render_image
from lidarphoto.core.simulation.render_scene import RenderOptions
from test_orthophoto import CRS, X0, Y0, _scene

GSD = 0.06


@pytest.fixture(scope="module")
def block(tmp_path_factory):
    """Two images of the house, from the south-west and the north-east, with their camera,
    EO table and DSM files."""
    folder = tmp_path_factory.mktemp("ortho")
    scene, dsm = _scene()
    cam = camera_from_dict({"name": "k1", "focal_mm": 10.0, "pixel_size_mm": 0.01,
                            "width_px": 800, "height_px": 600,
                            "distortion": {"model": "brown_conrady", "k1": 2e-4}})  # fmt: skip
    xyz = np.array([[X0 + 14.0, Y0 + 12.0, 60.0], [X0 + 27.0, Y0 + 28.0, 61.0]])
    opk = np.radians([[3.0, -2.0, 20.0], [-2.5, 2.0, 200.0]])
    eo = ExteriorOrientationTable(("sw", "ne"), np.array([0.0, 1.0]), ("a", "a"), xyz, opk,
                                  pyproj.CRS.from_user_input(CRS).to_wkt())  # fmt: skip
    images = folder / "images"
    for k, name in enumerate(eo.image_id):
        img = render_image(scene, cam, xyz[k], opk[k], RenderOptions(step_px=1, noise_dn=0.0))
        write_rgb_tiff(images / f"{name}.tif", img.rgb)
    write_camera_json(folder / "camera.json", cam)
    write_eo_csv(folder / "eo.csv", eo)
    write_dsm(folder / "dsm.tif", dsm)
    return {"folder": folder, "images": images, "cam": cam, "eo": eo, "dsm": dsm,
            "scene": scene}  # fmt: skip


def _args(b, out: Path, *extra: str) -> list[str]:
    f = b["folder"]
    return ["orthorectify", "--camera", str(f / "camera.json"), "--eo", str(f / "eo.csv"),
            "--images", str(b["images"]), "--dsm", str(f / "dsm.tif"), "--crs", CRS,
            "--gsd", str(GSD), "--output-folder", str(out), *extra]  # fmt: skip


def _read(path: Path):
    with RasterReader(path) as src:
        return src.info, src.read(), src.read_mask()


@pytest.fixture(scope="module")
def orthos(block, tmp_path_factory):
    out = tmp_path_factory.mktemp("orthos")
    assert cli_main(_args(block, out, "--true-ortho", "true")) == 0
    return out


def test_orthorectify_writes_one_true_orthophoto_per_image(block, orthos, capsys):
    names = sorted(p.name for p in orthos.iterdir())
    assert names == ["ne_ortho.tif", "sw_ortho.tif"]  # and no temporary file
    with RasterReader(orthos / "sw_ortho.tif") as src:
        info = src.info
        assert info.bands == 3 and info.dtype == np.uint8
        assert pyproj.CRS.from_wkt(info.crs_wkt).to_epsg() == 28992
        gt = info.geotransform
        assert gt[1] == GSD and gt[5] == -GSD
        assert round(gt[0] / GSD, 6) % 1 == 0 and round(gt[3] / GSD, 6) % 1 == 0  # aligned
        assert src.block_size() == (512, 512) and src.compression().upper() == "DEFLATE"
        assert src.overview_count() == len(overview_factors(info.width, info.height))
        meta = info.metadata
        assert meta["LIDARPHOTO_IMAGE_ID"] == "sw" and meta["LIDARPHOTO_TRUE_ORTHO"] == "yes"
        centre = [float(v) for v in meta["LIDARPHOTO_CENTRE"].split(",")]
        np.testing.assert_allclose(centre, block["eo"].xyz[0], atol=1e-9)
        mask = src.read_mask()
        assert 0.3 < mask.mean() < 1.0
        data = src.read()
        assert (data[:, ~mask] == 0).all() and data[:, mask].mean() > 40


def test_mosaic_fills_occlusions_from_the_other_view(block, orthos):
    """The mosaic of the two true orthophotos: ground hidden in one is taken from the other."""
    out = orthos.parent / "mosaic"
    out.mkdir()
    code = cli_main(["orthomosaic", "--orthophotos", str(orthos), "--output",
                     str(out / "m.tif"), "--seamlines-csv", str(out / "seams.csv")])  # fmt: skip
    assert code == 0
    info_m, mos, mask_m = _read(out / "m.tif")
    parts = {}
    for name in ("sw", "ne"):
        info, data, mask = _read(orthos / f"{name}_ortho.tif")
        gt = info.geotransform
        c0 = round((gt[0] - info_m.geotransform[0]) / GSD)
        r0 = round((info_m.geotransform[3] - gt[3]) / GSD)
        parts[name] = (r0, c0, data, mask)
    # where exactly one orthophoto has data, the mosaic is that orthophoto
    have = np.zeros((2, *mask_m.shape), bool)
    vals = np.zeros((2, 3, *mask_m.shape), np.uint8)
    for k, (r0, c0, data, mask) in enumerate(parts.values()):
        h, w = mask.shape
        have[k, r0 : r0 + h, c0 : c0 + w] = mask
        vals[k, :, r0 : r0 + h, c0 : c0 + w] = data
    assert np.array_equal(mask_m, have.any(axis=0))
    only = [have[k] & ~have[1 - k] for k in (0, 1)]
    for k in (0, 1):
        assert only[k].sum() > 500
        np.testing.assert_array_equal(mos[:, only[k]], vals[k][:, only[k]])
    # cells hidden in one view and seen in the other: both cases occur near the house
    occluded_sw = ~have[0] & have[1]
    assert occluded_sw.sum() > 1000
    # seamlines: one region per image, areas as counted
    rows = list(csv.DictReader(open(out / "seams.csv", encoding="utf-8")))
    assert sorted(r["image_id"] for r in rows) == ["ne", "sw"]
    assert sum(int(r["cells"]) for r in rows) == int(mask_m.sum())
    for r in rows:
        assert float(r["area"]) == pytest.approx(int(r["cells"]) * GSD**2)
        assert r["wkt"].startswith("MULTIPOLYGON (((")
        assert _wkt_area(r["wkt"]) == pytest.approx(float(r["area"]), rel=1e-9)


def _wkt_area(wkt: str) -> float:
    """Area of a WKT MultiPolygon (shoelace; holes subtracted by their orientation)."""
    body = wkt[len("MULTIPOLYGON ") :]
    total = 0.0
    for poly in body.strip("()").split(")), (("):
        for k, ring in enumerate(poly.strip("()").split("), (")):
            xy = np.array([[float(v) for v in p.split()] for p in ring.strip("()").split(",")])
            xy -= xy[0]  # centred: map coordinates of 1e5 would cost 1e-6 of the area
            a = 0.5 * abs(np.sum(xy[:-1, 0] * xy[1:, 1] - xy[1:, 0] * xy[:-1, 1]))
            total += a if k == 0 else -a
    return total


def test_mosaic_choice_is_the_most_nadir_view():
    """Three constant orthophotos on one grid: each cell comes from the one whose perspective
    centre is nearest horizontally (same flying height), checked against brute force; a hole
    in one (an occlusion) is filled by the next best."""
    cell = 0.5
    grid = Grid(1000.0, 2100.0, cell, 120, 200)
    centres = [(1020.0, 2060.0, 500.0), (1060.0, 2030.0, 500.0), (1080.0, 2075.0, 500.0)]
    srcs = [MosaicSource(f"i{k}", grid, c, 0.0, None) for k, c in enumerate(centres)]
    hole = np.zeros((grid.rows, grid.cols), bool)
    hole[40:60, 60:90] = True

    def read(k, win):
        c0, r0, w, h = win
        valid = np.ones((h, w), bool)
        if k == 1:
            valid &= ~hole[r0 : r0 + h, c0 : c0 + w]
        return np.full((1, h, w), 50 * (k + 1), np.uint8), valid

    tiles = list(mosaic_tiles(srcs, mosaic_grid(srcs), read, 1, np.uint8,
                              MosaicOptions(tile_px=64)))  # fmt: skip
    label = np.zeros((grid.rows, grid.cols), int)
    data = np.zeros((grid.rows, grid.cols), int)
    for t in tiles:
        h, w = t.label.shape
        label[t.row0 : t.row0 + h, t.col0 : t.col0 + w] = t.label
        data[t.row0 : t.row0 + h, t.col0 : t.col0 + w] = t.data[0]
    xs = grid.x0 + (np.arange(grid.cols) + 0.5) * cell
    ys = grid.y_top - (np.arange(grid.rows) + 0.5) * cell
    gx, gy = np.meshgrid(xs, ys)
    d = np.stack([np.hypot(gx - c[0], gy - c[1]) for c in centres])
    d[1][hole] = np.inf
    np.testing.assert_array_equal(label, np.argmin(d, axis=0))
    np.testing.assert_array_equal(data, 50 * (label + 1))
    assert (label[hole] != 1).all() and (label == 1).sum() > 1000


def test_mosaic_nadir_weighs_the_flying_height_and_needs_every_centre():
    """Centres at different heights: the choice is the smallest tangent of the nadir angle
    (horizontal distance / height), not the nearest centre; a source without a centre is
    refused for the nadir method (its distance would not compare with a tangent)."""
    grid = Grid(0.0, 100.0, 1.0, 100, 100)
    centres = [(20.0, 50.0, 100.0), (70.0, 50.0, 400.0)]  # the second is four times higher
    srcs = [MosaicSource(f"i{k}", grid, c, 0.0, None) for k, c in enumerate(centres)]

    def read(k, win):
        _c0, _r0, w, h = win
        return np.full((1, h, w), k + 1, np.uint8), np.ones((h, w), bool)

    label = np.zeros((grid.rows, grid.cols), int)
    for t in mosaic_tiles(srcs, grid, read, 1, np.uint8, MosaicOptions(tile_px=64)):
        h, w = t.label.shape
        label[t.row0 : t.row0 + h, t.col0 : t.col0 + w] = t.label
    xs = np.arange(grid.cols) + 0.5
    ys = grid.y_top - (np.arange(grid.rows) + 0.5)
    gx, gy = np.meshgrid(xs, ys)
    tan = np.stack([np.hypot(gx - c[0], gy - c[1]) / c[2] for c in centres])
    dist = np.stack([np.hypot(gx - c[0], gy - c[1]) for c in centres])
    np.testing.assert_array_equal(label, np.argmin(tan, axis=0))
    assert (np.argmin(tan, axis=0) != np.argmin(dist, axis=0)).sum() > 500  # it matters here
    srcs[0] = MosaicSource("i0", grid, None, 0.0, None)
    with pytest.raises(InputError, match="'i0' has no perspective centre"):
        list(mosaic_tiles(srcs, grid, read, 1, np.uint8, MosaicOptions(tile_px=64)))


def test_feathering_blends_linearly_across_the_seam():
    """Two constant orthophotos (100 and 200) with the seam half-way between their centres:
    across it the mosaic goes from 100 to 200 linearly over the feathering width."""
    cell = 1.0
    grid = Grid(0.0, 50.0, cell, 50, 100)
    srcs = [MosaicSource("a", grid, (25.0, 25.0, 1000.0), 0.0, None),
            MosaicSource("b", grid, (75.0, 25.0, 1000.0), 0.0, None)]  # fmt: skip

    def read(k, win):
        _, _, w, h = win
        return np.full((1, h, w), 100.0 * (k + 1), np.float32), np.ones((h, w), bool)

    feather = 10.0
    row = None
    for t in mosaic_tiles(srcs, grid, read, 1, np.float32,
                          MosaicOptions(feather_px=feather, tile_px=32)):  # fmt: skip
        if t.row0 == 0:
            row = t.data[0, 20] if row is None else np.r_[row, t.data[0, 20]]
    x = np.arange(100) + 0.5  # cell centres; the seam is at x = 50
    want = np.clip(100 + 100 * (0.5 + (x - 50) / feather), 100, 200)
    np.testing.assert_allclose(row, want, atol=1e-4)


def test_bad_inputs_are_refused_before_writing(block, tmp_path):
    out = tmp_path / "out"
    # an image without exterior orientation: named
    extra = tmp_path / "imgs"
    extra.mkdir()
    for p in block["images"].iterdir():
        (extra / p.name).write_bytes(p.read_bytes())
    write_rgb_tiff(extra / "nw.tif", np.zeros((600, 800, 3), np.uint8))
    args = _args(block, out)
    args[args.index("--images") + 1] = str(extra)
    with pytest.raises(InputError, match=r"eo\.csv: no exterior orientation for image\(s\) nw"):
        run_job(orthorectify, _values(args))
    assert not out.exists() or not any(out.iterdir())
    # an image of another size than the camera: the file named
    write_rgb_tiff(extra / "nw.tif", np.zeros((300, 400, 3), np.uint8))
    eo = block["eo"]
    three = ExteriorOrientationTable(("sw", "ne", "nw"), np.arange(3.0), ("a",) * 3,
                                     np.vstack([eo.xyz, eo.xyz[:1]]),
                                     np.vstack([eo.opk, eo.opk[:1]]), eo.crs_wkt)  # fmt: skip
    write_eo_csv(tmp_path / "eo3.csv", three)
    args[args.index("--eo") + 1] = str(tmp_path / "eo3.csv")
    with pytest.raises(InputError, match=r"nw\.tif: the image is 400 x 300 px, the camera"):
        run_job(orthorectify, _values(args))
    assert not out.exists() or not any(out.iterdir())
    # a DSM whose heights are in NAP (RD New + NAP): the geoid grid is missing -> PROJ's reason
    nap = Dsm(block["dsm"].heights, block["dsm"].grid, pyproj.CRS.from_epsg(7415))
    write_dsm(tmp_path / "nap.tif", nap)
    args = _args(block, out)
    args[args.index("--dsm") + 1] = str(tmp_path / "nap.tif")
    try:  # whether PROJ has the NAP geoid grid here
        transformer_3d(pyproj.CRS.from_epsg(7415), pyproj.CRS.from_epsg(28992))
        missing = False
    except CrsError:
        missing = True
    if missing:
        with pytest.raises(CrsError, match=r"nap\.tif: the DSM .* cannot be brought into .*grid"):
            run_job(orthorectify, _values(args))
        assert not out.exists() or not any(out.iterdir())
    assert "nw" not in str(list(tmp_path.glob("**/*_ortho.tif")))


def test_dsm_in_another_crs_is_resampled(block, orthos, tmp_path, caplog):
    """The DSM in UTM 31N: resampled into RD New (warned); the orthophoto matches the one made
    on the RD DSM (phase correlation on the ground)."""
    utm = reproject_dsm(block["dsm"], "EPSG:32631")
    write_dsm(tmp_path / "utm.tif", utm)
    args = _args(block, tmp_path / "out", "--true-ortho", "false")
    args[args.index("--dsm") + 1] = str(tmp_path / "utm.tif")
    with caplog.at_level(logging.WARNING, logger="lidarphoto"):
        res = run_job(orthorectify, _values(args))
    assert res.results["IMAGE_COUNT"] == 2
    assert any("resampled into" in r.message for r in caplog.records)
    info_a, a, ma = _read(tmp_path / "out" / "sw_ortho.tif")
    plain = tmp_path / "plain"
    run_job(orthorectify, _values(_args(block, plain)))
    info_b, b, mb = _read(plain / "sw_ortho.tif")
    # the two grids are aligned on multiples of the GSD: offset of b's first cell in a
    dc = round((info_b.geotransform[0] - info_a.geotransform[0]) / GSD)
    dr = round((info_a.geotransform[3] - info_b.geotransform[3]) / GSD)
    both = np.zeros_like(mb)
    sub_a = ma[max(dr, 0) :, max(dc, 0) :]
    h, w = min(sub_a.shape[0], mb.shape[0] - max(-dr, 0)), min(sub_a.shape[1],
                                                            mb.shape[1] - max(-dc, 0))  # fmt: skip
    both[max(-dr, 0) : max(-dr, 0) + h, max(-dc, 0) : max(-dc, 0) + w] = sub_a[:h, :w]
    both &= mb & (block["dsm"].height_at(*_centres(info_b)).reshape(mb.shape) < 3.0)
    inner = cv2.erode(both.astype(np.uint8), np.ones((129, 129), np.uint8), borderValue=0)
    rows, cols = np.nonzero(inner)  # centres of 128-cell squares of ground seen in both
    assert rows.size
    r0, c0 = int(rows[rows.size // 2]) - 64, int(cols[rows.size // 2]) - 64
    assert both[r0 : r0 + 128, c0 : c0 + 128].all()
    gb = b[1, r0 : r0 + 128, c0 : c0 + 128].astype(float)
    ga = a[1, r0 + dr : r0 + dr + 128, c0 + dc : c0 + dc + 128].astype(float)
    dx, dy, _ = phase_correlation(gb, ga)
    assert math.hypot(dx, dy) < 0.1


def _centres(info) -> tuple[np.ndarray, np.ndarray]:
    gt = info.geotransform
    xs = gt[0] + (np.arange(info.width) + 0.5) * gt[1]
    ys = gt[3] + (np.arange(info.height) + 0.5) * gt[5]
    gx, gy = np.meshgrid(xs, ys)
    return gx.ravel(), gy.ravel()


def test_dsm_not_covering_the_image_is_warned(block, tmp_path, caplog):
    d = block["dsm"]
    g = d.grid
    half = Dsm(d.heights[:, : g.cols // 2].copy(), Grid(g.x0, g.y_top, g.cell, g.rows,
                                                       g.cols // 2), d.crs)  # fmt: skip
    write_dsm(tmp_path / "half.tif", half)
    args = _args(block, tmp_path / "out")
    args[args.index("--dsm") + 1] = str(tmp_path / "half.tif")
    with caplog.at_level(logging.WARNING, logger="lidarphoto"):
        run_job(orthorectify, _values(args))
    assert any("does not cover all of 2 image(s)" in r.message and "sw " in r.message
               for r in caplog.records)  # fmt: skip
    info, _, _ = _read(tmp_path / "out" / "sw_ortho.tif")
    # the orthophoto stops at the DSM's last cell centre
    east = info.geotransform[0] + info.width * GSD
    assert east <= g.x0 + (g.cols // 2) * g.cell + GSD


def test_cancel_leaves_nothing(block, tmp_path):
    calls = {"n": 0}

    def stop() -> bool:
        calls["n"] += 1
        return calls["n"] > 3

    with pytest.raises(Cancelled):
        run_job(orthorectify, _values(_args(block, tmp_path / "out")), should_stop=stop)
    assert not any((tmp_path / "out").iterdir())


def test_foreign_grids_are_refused(tmp_path):
    for name, x0 in (("a", 0.0), ("b", 0.25)):
        with GeoTiffWriter(tmp_path / f"{name}.tif", 10, 10, 1, np.uint8,
                           (x0, 1.0, 0.0, 10.0, 0.0, -1.0), CRS) as w:  # fmt: skip
            w.write(np.ones((10, 10), np.uint8))
    with pytest.raises(InputError, match="not aligned"):
        run_job(orthomosaic, {"ORTHOPHOTOS": [str(tmp_path / "a.tif"), str(tmp_path / "b.tif")],
                              "OUTPUT": str(tmp_path / "m.tif")})  # fmt: skip
    assert not (tmp_path / "m.tif").exists()


def _values(argv: list[str]) -> dict:
    """Command-line arguments -> run_job values (what the command line does)."""
    from lidarphoto.core.cli import build_parser

    args = build_parser().parse_args(argv)
    return {p.name: getattr(args, p.name) for p in args.job.SPEC.params
            if p.kind != "sink" and getattr(args, p.name) is not None}  # fmt: skip


def test_levels_finished_during_the_next_image_are_whole(block, tmp_path):
    """The first image's overview levels are written while the second image is computed:
    each file equals the one made by a job of that image alone."""
    from test_raster_overviews import _levels

    both = tmp_path / "both"
    run_job(orthorectify, _values(_args(block, both)))
    for name in ("ne", "sw"):
        alone = tmp_path / name
        args = _args(block, alone)
        args[args.index("--images") + 1] = str(block["images"] / f"{name}.tif")
        run_job(orthorectify, _values(args))
        a, b = both / f"{name}_ortho.tif", alone / f"{name}_ortho.tif"
        ia, da, ma = _read(a)
        _, db, mb = _read(b)
        np.testing.assert_array_equal(da, db)
        np.testing.assert_array_equal(ma, mb)
        n = len(overview_factors(ia.width, ia.height))
        assert n >= 1
        for (la, mla), (lb, mlb) in zip(_levels(a, n), _levels(b, n)):
            np.testing.assert_array_equal(la, lb)
            np.testing.assert_array_equal(mla, mlb)


def test_a_failure_writing_the_levels_leaves_nothing(block, tmp_path, monkeypatch):
    from lidarphoto.core.io import raster_write

    def fail(*args):
        raise OSError("disk full (simulated)")

    monkeypatch.setattr(raster_write, "_write_levels_rasterio", fail)
    monkeypatch.setattr(raster_write, "_write_levels_gdal", fail)
    with pytest.raises(OSError, match="simulated"):
        run_job(orthorectify, _values(_args(block, tmp_path / "out")))
    assert not any((tmp_path / "out").iterdir())
