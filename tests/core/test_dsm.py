"""DSM from LAS/LAZ (highest return per cell, gaps filled), raster round trip, the surface."""

from __future__ import annotations

from pathlib import Path

import laspy
import numpy as np
import pyproj
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.grid import Grid
from lidarphoto.core.geometry.surface import Dsm
from lidarphoto.core.io import raster as raster_mod
from lidarphoto.core.io.dsm import dsm_from_las, load_dsm, read_dsm_raster, write_dsm
from lidarphoto.core.lidar.dsm import dsm_from_points

AHN3 = Path(__file__).resolve().parents[1] / "data" / "ahn3" / "ahn3_delft_crop60.laz"


def _reference_max(x, y, z, grid: Grid) -> np.ndarray:
    """Independent reference: ufunc.at over the cells."""
    out = np.full(grid.rows * grid.cols, -np.inf)
    np.maximum.at(out, grid.flat_index(x, y), z)
    return out.reshape(grid.rows, grid.cols)


def test_highest_point_per_cell_and_filled_gaps():
    rng = np.random.default_rng(5)
    x, y = rng.uniform(0, 20, 4000), rng.uniform(0, 10, 4000)
    z = rng.normal(5, 2, 4000)
    x[(x > 8) & (x < 12)] += 100  # an empty band, then bring the points back out of the box
    keep = x < 50
    x, y, z = x[keep], y[keep], z[keep]
    heights, grid = dsm_from_points(x, y, z, 1.0, fill=False)
    ref = _reference_max(x, y, z, grid)
    has = np.isfinite(ref)
    np.testing.assert_array_equal(heights[has], ref[has].astype(np.float32))
    assert np.isnan(heights[~has]).all() and (~has).sum() >= 30
    filled, _ = dsm_from_points(x, y, z, 1.0)
    assert np.isfinite(filled).all()
    np.testing.assert_array_equal(filled[has], heights[has])
    # pull-push fill interpolates: every filled cell lies within the range of valid ones
    assert filled[~has].min() >= heights[has].min() and filled[~has].max() <= heights[has].max()


def test_dsm_from_ahn3_laz():
    dsm = dsm_from_las(AHN3, 0.5, crs="EPSG:28992")
    las = laspy.read(AHN3)
    cls = np.asarray(las.classification)
    keep = ~np.isin(cls, (7, 18))
    x, y, z = (np.asarray(v, float)[keep] for v in (las.x, las.y, las.z))
    ref = _reference_max(x, y, z, dsm.grid)
    has = np.isfinite(ref)
    assert has.mean() > 0.9  # 14 points/m2 at 0.5 m cells: few empty cells (water, shadows)
    np.testing.assert_allclose(dsm.heights[has], ref[has], atol=1e-5)
    assert np.isfinite(dsm.heights).all()
    assert dsm.crs.to_epsg() == 28992 and dsm.grid.cell == 0.5
    assert dsm_from_las(AHN3, 0.5).crs.to_epsg() == 7415  # the file's own CRS
    # metres and the CRS unit are the same thing here
    np.testing.assert_array_equal(
        dsm_from_las(AHN3, 1.0, distance_unit="metre").heights, dsm_from_las(AHN3, 1.0).heights
    )


def _backends() -> list[str]:
    """The GDAL bindings importable here (osgeo in QGIS's Python, rasterio in the core's)."""
    found = []
    for name, module in (("gdal", "osgeo.gdal"), ("rasterio", "rasterio")):
        try:
            __import__(module)
            found.append(name)
        except ImportError:
            pass
    return found


@pytest.mark.parametrize("backend", _backends())
def test_geotiff_round_trip(tmp_path, monkeypatch, backend):
    monkeypatch.setenv("LIDARPHOTO_RASTER_BACKEND", backend)
    assert raster_mod.raster_backend() == backend
    z = np.arange(12, dtype=np.float32).reshape(3, 4) + 100.25
    z[1, 2] = np.nan
    for crs in ("EPSG:28992", pyproj.CRS.from_proj4("+proj=tmerc +lon_0=5 +ellps=GRS80")):
        src = Dsm(z, Grid(84900.0, 447650.0, 0.5, 3, 4), pyproj.CRS.from_user_input(crs))
        path = tmp_path / "dsm.tif"
        write_dsm(path, src)
        back = read_dsm_raster(path)
        np.testing.assert_array_equal(np.isnan(back.heights), np.isnan(z))
        np.testing.assert_array_equal(back.heights[~np.isnan(z)], z[~np.isnan(z)])
        assert back.grid == src.grid
        assert back.crs.equals(src.crs, ignore_axis_order=True)
    assert load_dsm(path, crs="EPSG:28992").crs.to_epsg() == 28992  # override


def test_surface_is_the_two_triangles_of_each_quad():
    z = np.array([[1.0, 3.0], [7.0, 2.0]], np.float32)
    d = Dsm(z, Grid(0.0, 2.0, 1.0, 2, 2))
    # centres: (0.5, 1.5) z=1, (1.5, 1.5) z=3, (0.5, 0.5) z=7, (1.5, 0.5) z=2
    np.testing.assert_allclose(d.height_at([0.5, 1.5, 0.5, 1.5], [1.5, 1.5, 0.5, 0.5]), z.ravel())
    # the diagonal from (r, c) to (r + 1, c + 1) is an edge of both triangles
    np.testing.assert_allclose(d.height_at([1.0], [1.0]), [(1.0 + 2.0) / 2])
    # triangle 0 (u >= v) holds (0,0),(1,0),(1,1): at u=0.75, v=0.25
    np.testing.assert_allclose(d.height_at([1.25], [1.25]), [1 + 2 * 0.75 + (2 - 3) * 0.25])
    # triangle 1 (u <= v) holds (0,0),(0,1),(1,1): at u=0.25, v=0.75
    np.testing.assert_allclose(d.height_at([0.75], [0.75]), [1 + (2 - 7) * 0.25 + 6 * 0.75])
    assert np.isnan(d.height_at([0.2], [1.0])).all()  # outside the centres' hull


def test_bad_rasters(tmp_path):
    with pytest.raises(InputError, match="not found"):
        read_dsm_raster(tmp_path / "none.tif")
    bad = tmp_path / "bad.tif"
    bad.write_bytes(b"not a tiff at all")
    with pytest.raises(InputError, match=r"bad\.tif: not a readable raster"):
        load_dsm(bad)
    with pytest.raises(InputError, match="cell size"):
        dsm_from_points([0.0], [0.0], [0.0], 0.0)
