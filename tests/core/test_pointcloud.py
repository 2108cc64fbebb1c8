"""LAS/LAZ I/O through laspy: info, CRS and units, chunked reads, lossless rewrites, bad input."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import laspy
import numpy as np
import pyproj
import pytest
from lidarphoto.core.errors import Cancelled, CrsError, InputError
from lidarphoto.core.io.pointcloud import read_cloud, read_info, read_points, write_cloud

DATA = Path(__file__).resolve().parents[1] / "data"
AHN3 = DATA / "ahn3" / "ahn3_delft_crop60.laz"
SAMP11 = DATA / "isprs" / "samp11.laz"
TEST_DATA = Path(__file__).resolve().parents[1] / "data"
BOTH_VLRS = TEST_DATA / "laspy" / "file_with_both_wkt_and_geotiff_vlrs.las"
AUTZEN_TRIM = TEST_DATA / "autzen" / "autzen_trim.laz"
NO_CRS = TEST_DATA / "laspy" / "simple.las"
US_FOOT = 1200.0 / 3937.0


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if ".part" in p.name)


def test_info_crs_from_geotiff_keys_in_metres():
    info = read_info(SAMP11)
    assert info.crs.to_epsg() == 32632
    assert (info.version, info.point_format, info.point_count) == ("1.2", 1, 38010)
    assert info.horizontal_unit == "metre"
    assert info.unit_to_metre == 1.0 and info.vertical_unit_to_metre == 1.0
    assert not info.has_return_numbers  # the ISPRS samples carry no return numbers
    assert {"X", "Y", "Z", "classification"} <= set(info.dimensions)


def test_compound_crs_written_into_the_crop_is_read_back():
    info = read_info(AHN3)
    assert info.crs.to_epsg() == 7415
    assert info.horizontal_unit == "metre" and info.vertical_unit_to_metre == 1.0
    assert info.has_return_numbers
    assert np.all(info.maxs - info.mins <= [60.0, 60.0, 30.0])


def test_wkt_preferred_and_us_survey_feet():
    info = read_info(BOTH_VLRS)
    assert info.version == "1.4" and info.point_format == 6
    assert "Nebraska" in info.crs.name  # the WKT VLR (the GeoTIFF keys give EPSG:32104, metres)
    assert info.horizontal_unit == "US survey foot"
    assert info.unit_to_metre == pytest.approx(US_FOOT, rel=1e-12)
    assert info.vertical_unit_to_metre == pytest.approx(US_FOOT, rel=1e-12)  # VerticalUnitsGeoKey


def test_international_feet_from_esri_wkt():
    info = read_info(AUTZEN_TRIM)
    assert info.horizontal_unit == "foot"
    assert info.unit_to_metre == pytest.approx(0.3048, rel=1e-12)
    arrays, info = read_points(AUTZEN_TRIM, ("x", "y", "z", "return_number"))
    assert info.has_return_numbers
    # the file's extent is 1177 x 563 ft: in feet, not metres
    assert np.ptp(arrays["x"]) == pytest.approx(1177.46, abs=0.05)


def test_override_crs_and_refuse_geographic():
    assert read_info(SAMP11, crs="EPSG:25832").crs.to_epsg() == 25832
    # Vaihingen (UTM 32N) labelled as Oregon in feet: refused, the extent is not in Oregon
    with pytest.raises(CrsError, match=r"samp11\.laz: the cloud .* outside the area of use "
                       r"of 'NAD83\(HARN\) / Oregon GIC Lambert \(ft\)'"):
        read_info(SAMP11, crs=pyproj.CRS.from_epsg(2994))
    with pytest.raises(CrsError, match="geographic"):
        read_info(SAMP11, crs=4326)
    with pytest.raises(CrsError, match="not a valid CRS"):
        read_info(SAMP11, crs="EPSG:999999")


def test_chunked_read_equals_laspy(tmp_path):
    las = laspy.read(AHN3)
    arrays, info = read_points(
        AHN3, ("x", "y", "z", "classification", "return_number", "gps_time"), chunk_size=7000
    )
    assert arrays["x"].dtype == np.float64 and arrays["classification"].dtype == np.uint8
    np.testing.assert_array_equal(arrays["x"], las.x)
    np.testing.assert_array_equal(arrays["z"], las.z)
    np.testing.assert_array_equal(arrays["classification"], las.classification)
    np.testing.assert_array_equal(arrays["gps_time"], las.gps_time)
    assert info.has_return_numbers


def test_unknown_field_names_the_column():
    with pytest.raises(InputError, match="height_above_ground"):
        read_points(AHN3, ("x", "height_above_ground"))


@pytest.mark.parametrize("suffix", [".las", ".laz"])
def test_rewrite_keeps_every_dimension_and_vlr(tmp_path, suffix):
    src = laspy.read(AHN3)
    n = len(src.points)
    rng = np.random.default_rng(1)
    cls = rng.integers(0, 20, n).astype(np.uint8)
    hag = rng.normal(size=n).astype(np.float32)
    pid = rng.integers(-5, 500, n).astype(np.int32)
    dst = tmp_path / f"out{suffix}"
    seen = []
    write_cloud(
        AHN3,
        dst,
        classification=cls,
        extra={"height_above_ground": hag, "plane_id": pid},
        chunk_size=9000,
        progress=seen.append,
    )
    assert seen[-1] == 1.0 and len(seen) == 4
    out = laspy.read(dst)
    assert out.header.are_points_compressed == (suffix == ".laz")
    assert out.header.version == src.header.version
    assert out.header.point_format.id == src.header.point_format.id
    for name in src.point_format.dimension_names:
        if name != "classification":
            np.testing.assert_array_equal(np.asarray(out[name]), np.asarray(src[name]), name)
    np.testing.assert_array_equal(out.classification, cls)
    assert out.height_above_ground.dtype == np.float32
    np.testing.assert_array_equal(out.height_above_ground, hag)
    assert out.plane_id.dtype == np.int32
    np.testing.assert_array_equal(out.plane_id, pid)
    src_vlrs = [(v.user_id, v.record_id) for v in src.header.vlrs if v.record_id != 22204]
    out_vlrs = [(v.user_id, v.record_id) for v in out.header.vlrs]
    assert all(v in out_vlrs for v in src_vlrs)
    assert out.header.parse_crs().to_epsg() == 7415
    np.testing.assert_allclose(out.header.mins, src.header.mins)
    assert out.header.system_identifier == src.header.system_identifier
    assert out.header.generating_software == src.header.generating_software
    assert _leftovers(tmp_path) == []

    # rewriting in place overwrites an existing extra dimension of the same dtype
    write_cloud(dst, dst, extra={"height_above_ground": np.zeros(n, np.float32)})
    again = laspy.read(dst)
    assert list(again.point_format.extra_dimension_names) == ["height_above_ground", "plane_id"]
    assert not again.height_above_ground.any()
    np.testing.assert_array_equal(again.plane_id, pid)


def test_rewrite_las14_keeps_wkt(tmp_path):
    dst = tmp_path / "out.laz"
    src = laspy.read(BOTH_VLRS)
    write_cloud(BOTH_VLRS, dst, extra={"h": np.ones(len(src.points), np.float64)})
    out = laspy.read(dst)
    assert out.header.version == "1.4" and out.header.point_format.id == 6
    assert out.header.global_encoding.wkt == src.header.global_encoding.wkt
    assert out.header.parse_crs() == src.header.parse_crs()
    np.testing.assert_array_equal(out.scan_angle, src.scan_angle)


def test_las_1_0_is_read(tmp_path):
    dst = tmp_path / "v10.las"
    write_cloud(SAMP11, dst)
    with open(dst, "r+b") as fh:  # version minor byte of the public header block
        fh.seek(25)
        fh.write(bytes([0]))
    info = read_info(dst)
    assert info.version == "1.0" and info.point_count == 38010


def test_bad_arrays_and_names(tmp_path):
    n = read_info(SAMP11).point_count
    with pytest.raises(InputError, match="shape"):
        write_cloud(SAMP11, tmp_path / "a.laz", classification=np.ones(n - 1, np.uint8))
    with pytest.raises(InputError, match="0-31"):
        write_cloud(SAMP11, tmp_path / "a.laz", classification=np.full(n, 40, np.uint8))
    with pytest.raises(InputError, match="standard dimension"):
        write_cloud(SAMP11, tmp_path / "a.laz", extra={"intensity": np.ones(n, np.uint16)})
    with pytest.raises(InputError, match=r"\.las or \.laz"):
        write_cloud(SAMP11, tmp_path / "a.txt")
    assert list(tmp_path.iterdir()) == []


def test_missing_empty_and_zero_point_files(tmp_path):
    with pytest.raises(InputError, match="not found") as err:
        read_info(tmp_path / "nope.laz")
    assert "nope.laz" in str(err.value)
    empty = tmp_path / "empty.laz"
    empty.write_bytes(b"")
    with pytest.raises(InputError, match="empty"):
        read_points(empty)
    zero = tmp_path / "zero.las"
    header = laspy.LasHeader(point_format=1, version="1.2")
    header.add_crs(pyproj.CRS.from_epsg(28992))
    laspy.LasData(header).write(zero)
    with pytest.raises(InputError, match="no points") as err:
        read_points(zero)
    assert "zero.las" in str(err.value)
    garbage = tmp_path / "garbage.las"
    garbage.write_bytes(b"not a las file at all" * 20)
    with pytest.raises(InputError, match="cannot read"):
        read_info(garbage)


def test_unsupported_version(tmp_path):
    dst = tmp_path / "v19.las"
    write_cloud(SAMP11, dst)
    with open(dst, "r+b") as fh:
        fh.seek(25)
        fh.write(bytes([9]))
    with pytest.raises(InputError, match="version") as err:
        read_info(dst)
    assert "v19.las" in str(err.value)


def test_no_crs_asks_for_one(tmp_path):
    src = laspy.read(AHN3)
    bare = tmp_path / "bare.las"
    header = laspy.LasHeader(point_format=src.header.point_format, version="1.2")
    header.scales, header.offsets = src.header.scales, src.header.offsets
    data = laspy.LasData(header)
    data.points = src.points[:1000].copy()
    data.write(bare)
    with pytest.raises(CrsError, match="give the CRS") as err:
        read_points(bare)
    assert "bare.las" in str(err.value)
    arrays, info = read_points(bare, crs="EPSG:7415")
    assert info.crs.to_epsg() == 7415 and len(arrays["x"]) == 1000
    info = read_info(bare, require_crs=False)
    assert info.crs is None and info.horizontal_unit == "unknown"


def test_corrupt_laz_leaves_no_output(tmp_path):
    broken = tmp_path / "broken.laz"
    raw = AHN3.read_bytes()
    broken.write_bytes(raw[: len(raw) // 2])  # header intact, point chunks cut
    with pytest.raises(InputError, match=r"broken\.laz"):
        read_points(broken)
    out = tmp_path / "out" / "result.laz"
    out.parent.mkdir()
    with pytest.raises(InputError, match=r"broken\.laz"):
        write_cloud(broken, out)
    assert list(out.parent.iterdir()) == []


def test_cancel_leaves_no_output(tmp_path):
    calls = []

    def stop() -> bool:
        calls.append(1)
        return len(calls) > 2

    out = tmp_path / "c.laz"
    shutil.copy(AHN3, tmp_path / "src.laz")
    with pytest.raises(Cancelled):
        write_cloud(tmp_path / "src.laz", out, chunk_size=5000, should_stop=stop)
    assert sorted(os.listdir(tmp_path)) == ["src.laz"]
    with pytest.raises(Cancelled):
        read_points(AHN3, chunk_size=5000, should_stop=lambda: True)


# ----------------------------------------------------------------------------- read once, write
def test_read_cloud_keeps_the_records_and_gives_the_arrays():
    cloud = read_cloud(AHN3, chunk_size=7000)
    las = laspy.read(AHN3)
    assert len(cloud) == len(las.points) and len(cloud.chunks) == 6  # 35231 in 7000s
    assert cloud.info.has_return_numbers and cloud.info.record_size == 28
    for name in ("x", "y", "z", "classification", "return_number", "gps_time", "intensity"):
        np.testing.assert_array_equal(cloud.values(name), np.asarray(las[name]), name)
    assert cloud.values("x").dtype == np.float64
    with pytest.raises(InputError, match="height_above_ground"):
        cloud.values("height_above_ground")
    isprs = read_cloud(SAMP11)
    assert not isprs.info.has_return_numbers  # every return number is 0


@pytest.mark.parametrize("suffix", [".las", ".laz"])
def test_copy_from_memory_equals_the_copy_from_the_file(tmp_path, suffix):
    """write_cloud(points=...) writes what decoding the file again would: the same records,
    header fields and VLRs, the new classification, and with no extra dimension the same
    point format (each chunk written as it was read)."""
    cloud = read_cloud(AHN3, chunk_size=10_000)
    n = len(cloud)
    cls = np.random.default_rng(3).integers(0, 20, n).astype(np.uint8)
    from_file, from_memory = tmp_path / f"f{suffix}", tmp_path / f"m{suffix}"
    write_cloud(AHN3, from_file, classification=cls)
    seen = []
    write_cloud(AHN3, from_memory, classification=cls, points=cloud, progress=seen.append)
    assert seen == [10_000 / n, 20_000 / n, 30_000 / n, 1.0]
    a, b = laspy.read(from_file), laspy.read(from_memory)
    assert b.point_format.id == a.point_format.id == 1 and b.point_format.size == 28
    np.testing.assert_array_equal(a.points.array, b.points.array)
    np.testing.assert_array_equal(b.classification, cls)
    assert [v.record_id for v in a.header.vlrs] == [v.record_id for v in b.header.vlrs]
    np.testing.assert_allclose(a.header.mins, b.header.mins)
    assert list(a.header.number_of_points_by_return) == list(b.header.number_of_points_by_return)
    # an extra dimension changes the point format: copied field by field, chunk by chunk
    hag = np.linspace(-1, 1, n).astype(np.float32)
    write_cloud(AHN3, from_memory, extra={"height_above_ground": hag}, points=cloud)
    c = laspy.read(from_memory)
    assert c.point_format.id == 1 and list(c.point_format.extra_dimension_names) == [
        "height_above_ground"
    ]
    np.testing.assert_array_equal(c.height_above_ground, hag)
    np.testing.assert_array_equal(c.gps_time, a.gps_time)
    assert _leftovers(tmp_path) == []


def test_cancel_while_writing_from_memory_leaves_no_output(tmp_path):
    cloud = read_cloud(AHN3, chunk_size=5000)
    calls = []

    def stop() -> bool:
        calls.append(1)
        return len(calls) > 2

    with pytest.raises(Cancelled):
        write_cloud(AHN3, tmp_path / "c.laz", points=cloud, should_stop=stop)
    assert os.listdir(tmp_path) == []
    with pytest.raises(Cancelled):
        read_cloud(AHN3, chunk_size=5000, should_stop=lambda: True)


def _synthetic_las(path: Path, version: str, fmt: int, scale: float, seed: int) -> None:
    """Random records (every dimension random bytes, then X Y Z and returns set): negative and
    positive coordinates, return numbers 0 to the field's largest; ``scale`` may be negative."""
    rng = np.random.default_rng(seed)
    header = laspy.LasHeader(version=version, point_format=fmt)
    header.scales = np.array([scale, abs(scale), scale])
    header.offsets = np.array([1000.0, -2000.0, 5.0])
    n = 2500
    raw = rng.integers(0, 256, (n, header.point_format.size), dtype=np.uint8)
    rec = laspy.PackedPointRecord(raw.view(header.point_format.dtype()).ravel(),
                                  header.point_format)  # fmt: skip
    for axis in "XYZ":
        rec[axis] = rng.integers(-(2**30), 2**30, n)
    top = 15 if fmt >= 6 else 7
    rec.return_number = rng.integers(0, top + 1, n)
    las = laspy.LasData(header, rec)
    las.write(path)


@pytest.mark.parametrize(
    ("version", "fmt", "scale"),
    [("1.2", 1, 0.01), ("1.2", 0, -0.001), ("1.4", 6, 0.001), ("1.4", 8, -0.01)],
)
@pytest.mark.parametrize("suffix", [".las", ".laz"])
def test_header_stats_are_laspys_byte_for_byte(tmp_path, monkeypatch, version, fmt, scale,
                                               suffix):  # fmt: skip
    """The compiled header statistics (core.io.las_stats) write the file laspy's own
    per-chunk growth writes, byte for byte: bounds (negative scales too), points by return (0
    and numbers above the header's slots left out), several chunks."""
    from lidarphoto.core.io import las_stats

    if not las_stats.AVAILABLE:
        pytest.skip("numba not installed: laspy's own path is the only one")
    src = tmp_path / f"src{suffix}"
    _synthetic_las(src, version, fmt, scale, seed=fmt)
    cloud = read_cloud(src, chunk_size=1000, require_crs=False)
    cls = np.random.default_rng(1).integers(0, 20, len(cloud)).astype(np.uint8)
    fast, slow = tmp_path / f"fast{suffix}", tmp_path / f"slow{suffix}"
    made = []
    real = las_stats.HeaderStats.for_writer
    monkeypatch.setattr(las_stats.HeaderStats, "for_writer",
                        classmethod(lambda c, w: made.append(1) or real(w)))  # fmt: skip
    write_cloud(src, fast, classification=cls, points=cloud, chunk_size=1000)
    assert made  # the fast path ran
    monkeypatch.setattr(las_stats.HeaderStats, "for_writer", classmethod(lambda c, w: None))
    write_cloud(src, slow, classification=cls, points=read_cloud(src, chunk_size=1000,
                                                                 require_crs=False))  # fmt: skip
    assert fast.read_bytes() == slow.read_bytes()
    h = laspy.read(fast).header
    assert h.point_count == 2500 and sum(h.number_of_points_by_return) < 2500  # 0s left out
