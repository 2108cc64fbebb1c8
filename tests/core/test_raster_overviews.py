"""core/io/raster_overviews.py: overviews computed from the blocks in memory against GDAL's
``BuildOverviews("AVERAGE")`` on the same raster and mask (through whichever binding this
Python has: rasterio in the core's venv, osgeo in QGIS's), bit for bit, on even and odd sides
(GDAL's fractional windows), masked cells, 8 and 16 bits, and blocks out of order."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.io.raster import RasterReader, overview_factors, raster_backend
from lidarphoto.core.io.raster_overviews import AVAILABLE, OverviewBuilder, average_level
from lidarphoto.core.io.raster_write import GeoTiffWriter

GT = (85000.0, 0.5, 0.0, 447100.0, 0.0, -0.5)


def _levels(path, n):
    """Every overview level of the file: (bands, rows, cols) data and the (rows, cols) mask."""
    out = []
    if raster_backend() == "gdal":
        from osgeo import gdal

        ds = gdal.Open(str(path))
        for k in range(n):
            bands = [ds.GetRasterBand(b + 1).GetOverview(k) for b in range(ds.RasterCount)]
            mask = ds.GetRasterBand(1).GetMaskBand().GetOverview(k).ReadAsArray() > 0
            out.append((np.stack([b.ReadAsArray() for b in bands]), mask))
        return out
    import rasterio

    for k in range(n):
        with rasterio.open(path, overview_level=k) as ds:
            out.append((ds.read(), ds.read_masks(1) > 0))
    return out


def _raster(h, w, dtype, seed=0):
    rng = np.random.default_rng(seed)
    top = 4096 if dtype == np.uint16 else 256
    data = rng.integers(0, top, (3, h, w)).astype(dtype)
    yy, xx = np.mgrid[:h, :w]
    # an ellipse of data (ragged edges at every level), single masked cells and a masked band
    mask = ((xx - w / 2) ** 2 / (0.45 * w) ** 2 + (yy - h / 2) ** 2 / (0.4 * h) ** 2) < 1
    mask &= rng.random((h, w)) > 0.05
    mask[h // 3 : h // 3 + 3] = False
    data[:, ~mask] = 0
    return data, mask


def _write(path, data, mask, in_memory, order=None, tile=128):
    _, h, w = data.shape
    blocks = [(r0, c0) for r0 in range(0, h, tile) for c0 in range(0, w, tile)]
    if order is not None:
        blocks = order(blocks)
    with GeoTiffWriter(path, w, h, 3, data.dtype, GT, "EPSG:28992", mask=True, tile=tile,
                       level=1, overviews_in_memory=in_memory) as out:  # fmt: skip
        for r0, c0 in blocks:
            out.write(data[:, r0 : r0 + tile, c0 : c0 + tile], c0, r0,
                      mask[r0 : r0 + tile, c0 : c0 + tile])  # fmt: skip


# the last: level 1 written in two parts
SIZES = [(768, 1024, np.uint8), (517, 779, np.uint8), (600, 1001, np.uint16),
         (1003, 640, np.uint8), (1300, 700, np.uint8)]  # fmt: skip


@pytest.mark.parametrize(("h", "w", "dtype"), SIZES)
def test_overviews_from_memory_equal_gdal_average(tmp_path, h, w, dtype):
    data, mask = _raster(h, w, dtype)
    _write(tmp_path / "gdal.tif", data, mask, in_memory=False)
    _write(tmp_path / "mem.tif", data, mask, in_memory=True)
    n = len(overview_factors(w, h))
    assert n >= 2
    gdal_levels, mem_levels = _levels(tmp_path / "gdal.tif", n), _levels(tmp_path / "mem.tif", n)
    for (gd, gm), (md, mm) in zip(gdal_levels, mem_levels):
        assert gd.dtype == md.dtype and gd.shape == md.shape
        assert gm.any() and not gm.all()  # masked cells at every level
        np.testing.assert_array_equal(mm, gm)
        np.testing.assert_array_equal(md, gd)  # bit for bit, masked cells (0) included
    with RasterReader(tmp_path / "mem.tif") as src:  # the full resolution is untouched
        np.testing.assert_array_equal(src.read(), data)
        np.testing.assert_array_equal(src.read_mask(), mask)
        assert src.overview_count() == n


def test_blocks_out_of_order_and_the_fallback(tmp_path):
    data, mask = _raster(517, 779, np.uint8, seed=1)
    _write(tmp_path / "gdal.tif", data, mask, in_memory=False)
    n = len(overview_factors(779, 517))
    ref = _levels(tmp_path / "gdal.tif", n)

    def columns_reversed(blocks):  # within each band of rows, right to left
        return sorted(blocks, key=lambda rc: (rc[0], -rc[1]))

    def bottom_up(blocks):  # rows already consumed come back: GDAL builds them instead
        return sorted(blocks, key=lambda rc: (-rc[0], rc[1]))

    for name, order in (("rev", columns_reversed), ("up", bottom_up)):
        _write(tmp_path / f"{name}.tif", data, mask, in_memory=True, order=order)
        for (gd, gm), (md, mm) in zip(ref, _levels(tmp_path / f"{name}.tif", n)):
            np.testing.assert_array_equal(mm, gm)
            np.testing.assert_array_equal(md, gd)


@pytest.mark.skipif(not AVAILABLE, reason="numba not installed")
def test_compiled_and_numpy_kernels_agree():
    data, mask = _raster(333, 517, np.uint8, seed=2)
    for backend in ("numba", "numpy"):
        b = OverviewBuilder(3, 333, 517, np.uint8, 3, backend=backend)
        for r0 in range(0, 333, 100):
            for c0 in range(0, 517, 100):
                b.add(data[:, r0 : r0 + 100, c0 : c0 + 100], mask[r0 : r0 + 100, c0 : c0 + 100],
                      c0, r0)  # fmt: skip
        got = b.levels()
        if backend == "numba":
            ref = got
            # and level by level from the whole arrays, numpy kernel, even sides (2 x 2 kernel)
            e, em = average_level(data[:, :332, :516], mask[:332, :516], backend="numpy")
            f, fm = average_level(data[:, :332, :516], mask[:332, :516], backend="numba")
            np.testing.assert_array_equal(e, f)
            np.testing.assert_array_equal(em, fm)
    for (a, am), (c, cm) in zip(ref, got):
        np.testing.assert_array_equal(a, c)
        np.testing.assert_array_equal(am, cm)


def test_pixel_interleaved_read(tmp_path):
    data, mask = _raster(300, 400, np.uint8, seed=3)
    _write(tmp_path / "a.tif", data, mask, in_memory=True)
    with RasterReader(tmp_path / "a.tif") as src:
        for f in (1, 2):
            a = src.read((8, 12, 200, 100), decimation=f, pixel_interleaved=True)
            np.testing.assert_array_equal(a, src.read((8, 12, 200, 100), decimation=f))
            assert np.moveaxis(a, 0, -1).flags.c_contiguous


def test_levels_beyond_the_memory_budget_are_gdals(tmp_path, monkeypatch):
    """A raster whose levels would not fit OVERVIEW_MEMORY_BYTES gets GDAL's overviews (the
    same pixels), one that fits gets them from memory."""
    from lidarphoto.core.io import raster_write

    data, mask = _raster(300, 400, np.uint8, seed=2)
    held = 150 * 200 * 4 * 4 // 3  # level 1 and its mask, and the deeper levels
    for budget, in_memory in ((held, True), (held - 1, False)):
        monkeypatch.setattr(raster_write, "OVERVIEW_MEMORY_BYTES", budget)
        w = GeoTiffWriter(tmp_path / f"{budget}.tif", 400, 300, 3, np.uint8, GT, "EPSG:28992",
                          mask=True, tile=128, level=1)  # fmt: skip
        assert (w._ovr is not None) == in_memory
        with w:
            w.write(data, 0, 0, mask)
    _write(tmp_path / "gdal.tif", data, mask, in_memory=False)
    n = len(overview_factors(400, 300))
    for path in (tmp_path / f"{held}.tif", tmp_path / f"{held - 1}.tif"):
        for (gd, gm), (md, mm) in zip(_levels(tmp_path / "gdal.tif", n), _levels(path, n)):
            np.testing.assert_array_equal(mm, gm)
            np.testing.assert_array_equal(md, gd)
