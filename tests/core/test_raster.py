"""core/io/raster.py through whichever GDAL binding this Python has (rasterio in the core's
venv, osgeo in QGIS's): layout of the written GeoTIFF, masks, metadata, window and averaged
reads, the polygons of a label raster, atomic writes."""

from __future__ import annotations

import os

import numpy as np
import pyproj
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.io.atomic import OutputSet
from lidarphoto.core.io.raster import RasterReader, overview_factors, polygonize, raster_backend
from lidarphoto.core.io.raster_write import GeoTiffWriter, write_rgb_tiff

GT = (85000.0, 0.5, 0.0, 447100.0, 0.0, -0.5)


def test_rgb_with_mask_metadata_and_overviews(tmp_path):
    rng = np.random.default_rng(0)
    data = rng.integers(0, 255, (3, 700, 900), dtype=np.uint8)
    mask = np.ones((700, 900), bool)
    mask[100:300, 200:500] = False
    data[:, ~mask] = 0
    path = tmp_path / "o.tif"
    with GeoTiffWriter(path, 900, 700, 3, np.uint8, GT, "EPSG:28992", mask=True,
                       photometric="RGB", metadata={"KEY": "value, 1"}) as w:  # fmt: skip
        for r0 in range(0, 700, 256):  # window by window, as the jobs write
            for c0 in range(0, 900, 256):
                w.write(data[:, r0 : r0 + 256, c0 : c0 + 256], c0, r0,
                        mask[r0 : r0 + 256, c0 : c0 + 256])  # fmt: skip
    with RasterReader(path) as src:
        info = src.info
        assert (info.width, info.height, info.bands, info.dtype) == (900, 700, 3, np.uint8)
        assert info.geotransform == GT and info.metadata["KEY"] == "value, 1"
        assert pyproj.CRS.from_wkt(info.crs_wkt).to_epsg() == 28992
        assert src.block_size() == (256, 256) and src.compression().upper() == "DEFLATE"
        assert src.overview_count() == len(overview_factors(900, 700)) == 2
        np.testing.assert_array_equal(src.read(), data)
        np.testing.assert_array_equal(src.read_mask(), mask)
        np.testing.assert_array_equal(src.read((10, 20, 30, 40), bands=[2]),
                                      data[1:2, 20:60, 10:40])  # fmt: skip
        # 4 x 4 averages, as the orthophotos read an image whose pixels are smaller than cells;
        # GDAL takes them from the overview of factor 4 (made from the one of factor 2: two
        # roundings) and leaves masked pixels out
        avg = src.read((40, 8, 400, 200), decimation=4).astype(float)
        ref = data[:, 8:208, 40:440].reshape(3, 50, 4, 100, 4).mean(axis=(2, 4))
        full = mask[8:208, 40:440].reshape(50, 4, 100, 4).all(axis=(1, 3))
        assert avg.shape == (3, 50, 100) and np.abs(avg - ref)[:, full].max() <= 1.0
        with pytest.raises(ValueError, match="outside"):
            src.read((800, 0, 200, 10))


def test_no_georeferencing_and_no_file(tmp_path):
    rgb = np.dstack([np.full((20, 30), v, np.uint8) for v in (10, 20, 30)])
    write_rgb_tiff(tmp_path / "i.tif", rgb)
    with RasterReader(tmp_path / "i.tif") as src:
        assert src.info.geotransform is None and src.info.crs_wkt == ""
        assert src.block_size() == (512, 512) and src.compression().upper() == "LZW"
        np.testing.assert_array_equal(np.moveaxis(src.read(), 0, 2), rgb)
    assert [p.name for p in tmp_path.iterdir()] == ["i.tif"]
    with pytest.raises(InputError, match="not found"):
        RasterReader(tmp_path / "none.tif")


def test_polygonize_follows_the_pixel_edges():
    lab = -np.ones((6, 8), np.int32)
    lab[1:3, 1:4] = 0
    lab[3:5, 2:7] = 1
    lab[0, 7] = 1  # a second part of region 1
    regions = polygonize(lab, GT)
    assert sorted(regions) == [0, 1]
    assert regions[0].startswith("MULTIPOLYGON (((")
    assert regions[1].count("((") == 2  # two parts
    xs = sorted({float(v.split()[0]) for v in regions[0][16:].replace("(", "").replace(")", "")
                 .split(",")})  # fmt: skip
    assert xs == [GT[0] + 0.5, GT[0] + 2.0]  # the edges of columns 1 .. 3


def test_output_set_commits_the_geotiff_and_its_sidecars(tmp_path):
    crs = pyproj.CRS.from_proj4("+proj=tmerc +lon_0=5.3 +k=0.9996 +ellps=GRS80 +units=m")
    target = tmp_path / "dsm.tif"
    with OutputSet({"OUT": target}, {}) as out:
        with GeoTiffWriter(out.path("OUT"), 4, 3, 1, np.float32, GT, crs, nodata=-9999.0) as w:
            w.write(np.arange(12, dtype=np.float32).reshape(3, 4))
        out.commit()
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names[0] == "dsm.tif" and all(n.startswith("dsm.tif") for n in names)
    with RasterReader(target) as src:
        assert pyproj.CRS.from_wkt(src.info.crs_wkt).equals(crs)
        assert src.info.nodata == -9999.0


def test_backend_prefers_osgeo_and_honours_the_override(monkeypatch):
    import importlib.util

    monkeypatch.delenv("LIDARPHOTO_RASTER_BACKEND", raising=False)
    have_gdal = importlib.util.find_spec("osgeo") is not None
    have_rio = importlib.util.find_spec("rasterio") is not None
    assert raster_backend() == ("gdal" if have_gdal else "rasterio")
    if have_rio:
        monkeypatch.setenv("LIDARPHOTO_RASTER_BACKEND", "rasterio")
        assert raster_backend() == "rasterio"
    if have_gdal:
        monkeypatch.setenv("LIDARPHOTO_RASTER_BACKEND", "GDAL")
        assert raster_backend() == "gdal"


def test_rasterio_keeps_its_own_proj_database_when_proj_data_points_elsewhere(tmp_path):
    """A QGIS set-up exports PROJ_DATA=/usr/share/proj (Debian's older proj.db); rasterio's
    wheel must still parse CRSs (the CI failure of 2026-11: 'DATABASE.LAYOUT.VERSION.MINOR')."""
    import subprocess
    import sys
    from pathlib import Path

    pytest.importorskip("rasterio")
    decoy = tmp_path / "proj"
    decoy.mkdir()
    (decoy / "proj.db").write_bytes(b"not a database")  # any foreign proj.db
    code = (
        "import numpy as np\n"
        "from lidarphoto.core.io.raster import RasterReader\n"
        "from lidarphoto.core.io.raster_write import GeoTiffWriter\n"
        f"p = {str(tmp_path / 'c.tif')!r}\n"
        "with GeoTiffWriter(p, 4, 3, 1, np.uint8, (85000.0, 1, 0, 447000.0, 0, -1),"
        " 'EPSG:28992') as w:\n"
        "    w.write(np.ones((1, 3, 4), np.uint8), 0, 0)\n"
        "print(RasterReader(p).info.crs_wkt[:40])\n"
    )
    env = dict(os.environ, PROJ_DATA=str(decoy), LIDARPHOTO_RASTER_BACKEND="rasterio")
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                          cwd=Path(__file__).resolve().parents[2], timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    assert "Amersfoort" in done.stdout
