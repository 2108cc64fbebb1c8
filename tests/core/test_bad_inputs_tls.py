"""The catalogue of bad inputs (test_bad_inputs.py), continued for the TLS algorithms, the
scan, LAS, camera and trajectory readers, and the check that an adjustment which rejected
more observations than data snooping's false alarms explain is not reported as passed.

Every case runs the command line and asserts the exit code, the one line on stderr with the
error that names the file (row, column or parameter) and what is wrong, nothing written (not
even a temporary) unless the case says what, and the input files unchanged.
"""

from __future__ import annotations

import re
import struct
from dataclasses import replace
from pathlib import Path

import laspy
import numpy as np
import pytest
from lidarphoto.core.cli import main
from lidarphoto.core.io.scans import read_scan
from lidarphoto.core.io.tls import write_tls_control_csv, write_tls_observations_csv
from lidarphoto.core.lsq.results import rejection_test
from lidarphoto.core.simulation.tls import (
    PAPER_APS,
    SCANNER_CLASSES,
    observe,
    paper_cube,
)
from lidarphoto.core.tls.calibration import CalibrationOptions, calibrate
from test_bad_inputs import AHN3, RD, Case, _monoplot_inputs, _traj
from test_bad_inputs import test_bad_input as run_case

ARCSEC = np.pi / (180.0 * 3600.0)


# ----------------------------------------------------------------------------- scans
def _ply_head(n: int, fmt: str = "ascii", extra: str = "") -> bytes:
    return (f"ply\nformat {fmt} 1.0\ncomment a scan\nelement vertex {n}\nproperty double x\n"
            f"property double y\nproperty double z\n{extra}end_header\n").encode()  # fmt: skip


def _points(n: int = 100) -> np.ndarray:
    """``n`` points 2 to 5 m around the scanner (a scan's order of size)."""
    rng = np.random.default_rng(3)
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1)[:, None] * rng.uniform(2.0, 5.0, (n, 1))


def _binary_ply(path: Path, xyz: np.ndarray, cut: int = 0, intensity=None) -> Path:
    fields = [("x", "<f8"), ("y", "<f8"), ("z", "<f8")]
    extra = ""
    if intensity is not None:
        fields.append(("intensity", "<f4"))
        extra = "property float intensity\n"
    rec = np.zeros(len(xyz), dtype=fields)
    rec["x"], rec["y"], rec["z"] = xyz.T
    if intensity is not None:
        rec["intensity"] = intensity
    raw = rec.tobytes()
    path.write_bytes(_ply_head(len(xyz), "binary_little_endian", extra) + raw[: len(raw) - cut])
    return path


def _ascii_ply(path: Path, lines: list[str], n: int | None = None) -> Path:
    body = "".join(line + "\n" for line in lines).encode()
    path.write_bytes(_ply_head(len(lines) if n is None else n) + body)
    return path


def _extract(scan: Path, out: Path) -> list[str]:
    if scan.suffix == ".e57":
        pytest.importorskip("pye57")
    return ["extracttlstargets", "--scans", str(scan), "--output", str(out / "targets.csv")]


def _e57(path: Path, cut: int | None = None, garbage: bool = False) -> Path:
    """A small E57 scan written by pye57, cut to ``cut`` bytes, or bytes that are no E57."""
    if garbage:
        path.write_bytes(b"not an E57 file " * 400)
        return path
    pye57 = pytest.importorskip("pye57")
    xyz = _points(1000)
    e57 = pye57.E57(str(path), mode="w")
    e57.write_scan_raw({"cartesianX": xyz[:, 0], "cartesianY": xyz[:, 1],
                        "cartesianZ": xyz[:, 2]})  # fmt: skip
    e57.close()
    if cut is not None:
        path.write_bytes(path.read_bytes()[:cut])
    return path


def _las_scan(path: Path, scale: float) -> Path:
    """A LAS scan (point format 1) whose header's x scale factor is ``scale``."""
    header = laspy.LasHeader(point_format=1, version="1.2")
    header.scales, header.offsets = np.full(3, 0.0001), np.zeros(3)
    las = laspy.LasData(header)
    xyz = _points(500)
    las.x, las.y, las.z = xyz.T
    las.write(str(path))
    raw = bytearray(path.read_bytes())
    raw[131:139] = struct.pack("<d", scale)  # LAS 1.2: x scale factor at byte 131
    path.write_bytes(bytes(raw))
    return path


def _camera_text(inp: Path, text: str | bytes) -> list[str]:
    argv = _monoplot_inputs(inp) + ["--dsm-crs", RD]
    cam = inp / "camera.json"
    if isinstance(text, bytes):
        cam.write_bytes(text)
    else:
        cam.write_text(text, encoding="utf-8")
    return argv


def _traj_file(inp: Path, text: str) -> list[str]:
    argv = _traj(inp, ["a,0,,85000,447500,500,0,0,0"])
    (inp / "traj.csv").write_text(text, encoding="utf-8")
    return argv


# ----------------------------------------------------------------------------- TLS network
def _cube(
    inp: Path,
    extra_aps: dict[str, float],
    seed: int = 1,
    sigma_factor: float = 1.3,
    blunders: int = 0,
) -> tuple[Path, Path]:
    """The paper's cube with a 3 x 3 target grid per face (162 observations from three
    stations) observed with a high-end scanner's noise, its observation sigmas declared
    ``sigma_factor`` times the noise (a cautious user), the paper's APs plus ``extra_aps``
    in the observations; the observation and control tables."""
    truth = paper_cube(grid=(3, 3), aps={**PAPER_APS, **extra_aps})
    obs, _ = observe(truth, *SCANNER_CLASSES["high_end"], rng=seed, blunders=blunders)
    obs = replace(obs, cov=obs.cov * sigma_factor**2)
    write_tls_observations_csv(inp / "obs.csv", obs)
    write_tls_control_csv(inp / "control.csv", truth.control())
    return inp / "obs.csv", inp / "control.csv"


#: A cyclic range error of 4 mm (Lichti's a2 term, sin(4 pi rho / 1.2 m)): the paper's AP set
#: (a0, b1, b2, c0) cannot represent it.
CYCLIC_ERROR = {"a2": 0.004}


def _tls_args(obs: Path, control: Path, out: Path, *extra: str) -> list[str]:
    return ["tlscalibration", "--observations", str(obs), "--control", str(control),
            "--levelled", "false", "--output-stations", str(out / "stations.csv"),
            "--output-aps", str(out / "aps.csv"), "--output-residuals", str(out / "v.csv"),
            "--output-html", str(out / "report.html"), *extra]  # fmt: skip


def _tls_table(inp: Path, out: Path, columns: str, rows: list[str]) -> list[str]:
    """tlscalibration on a table of station S1 with ``columns`` and ``rows``."""
    lines = [f"station_id,target_id,{columns}"]
    lines += [f"S1,T{k + 1},{r}" for k, r in enumerate(rows)]
    (inp / "obs.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    (inp / "control.csv").write_text("target_id,X,Y,Z\nT1,0,0,0\n", encoding="utf-8")
    return _tls_args(inp / "obs.csv", inp / "control.csv", out)


# ----------------------------------------------------------------------------- the cases
CASES = [
    # -- PLY scans: empty, truncated, not finite, not PLY, not in a scanner frame
    Case("empty PLY", lambda i, o, f: _extract(_empty(i / "s1.ply"), o),
         r"s1\.ply: empty file \(0 bytes\)$"),
    Case("PLY without vertices", lambda i, o, f: _extract(_ascii_ply(i / "s1.ply", []), o),
         r"s1\.ply: the scan holds no points \(element vertex 0\)$"),
    Case("truncated binary PLY",
         lambda i, o, f: _extract(_binary_ply(i / "s1.ply", _points(), cut=50), o),
         r"s1\.ply: truncated: the file holds 97 of the 100 vertices its header declares \(24 "
         r"bytes each\)$"),
    Case("truncated ASCII PLY", lambda i, o, f: _extract(
        _ascii_ply(i / "s1.ply", ["1 2 3", "2 3 4"], n=3), o),
         r"s1\.ply: truncated: the file holds 2 of the 3 vertices its header declares$"),
    Case("PLY cut inside its header", lambda i, o, f: _extract(
        _write(i / "s1.ply", _ply_head(3)[:60]), o),
         r"s1\.ply: the PLY header has no end_header \(truncated file\?\)$"),
    Case("ASCII PLY line short of a value", lambda i, o, f: _extract(
        _ascii_ply(i / "s1.ply", ["1 2 3", "2 3", "3 4 5"]), o),
         r"s1\.ply, row 10: vertex 2: 2 value\(s\) \('2 3'\), the header declares 3 numbers "
         r"\(x, y, z\)$"),
    Case("NaN in a PLY", lambda i, o, f: _extract(
        _ascii_ply(i / "s1.ply", ["1 2 3", "nan 3 4", "3 4 5", "1 nan 1"]), o),
         r"s1\.ply: point 2 of 4 has coordinates that are not finite \(nan, 3, 4\); 2 point\(s\) "
         r"affected: remove the points without a return$"),
    Case("infinite intensity in a binary PLY", lambda i, o, f: _extract(_binary_ply(
        i / "s1.ply", _points(), intensity=np.r_[np.ones(40), np.inf, np.ones(59)]), o),
         r"s1\.ply: point 41 of 100 has an intensity that is not finite \(inf\); 1 point\(s\) "
         r"affected$"),
    Case("text file named .ply", lambda i, o, f: _extract(_write(i / "s1.ply", b"1 2 3\n" * 9), o),
         r"s1\.ply: not a PLY file \(no 'ply' magic line\)$"),
    Case("unknown PLY format", lambda i, o, f: _extract(_write(
        i / "s1.ply", _ply_head(3).replace(b"ascii", b"binary_middle_endian")), o),
         r"s1\.ply: unknown PLY format 'binary_middle_endian' \(ascii, binary_little_endian or "
         r"binary_big_endian\)$"),
    Case("registered scan in UTM", lambda i, o, f: _extract(
        _ascii_ply(i / "s1.ply", ["500001 7450002 3", "500002 7450001 4", "500003 7450000 5"]),
        o),
         r"s1\.ply: points lie up to 7467 km from the scanner's origin; a scan in its scanner's "
         r"own frame stays within 10 km: this one is registered or georeferenced \(export the "
         r"station unregistered\)$"),
    # -- E57 scans (pye57)
    Case("truncated E57", lambda i, o, f: _extract(_e57(i / "s1.e57", cut=7000), o),
         r"s1\.e57: cannot read as E57 \(truncated or corrupt file\?\): size in file header not "
         r"same as actual \(ErrorBadFileLength\)$"),
    Case("bytes that are no E57", lambda i, o, f: _extract(_e57(i / "s1.e57", garbage=True), o),
         r"s1\.e57: cannot read as E57 \(truncated or corrupt file\?\): checksum mismatch, file "
         r"is corrupted \(ErrorBadChecksum\)$"),
    Case("empty E57", lambda i, o, f: _extract(_empty(i / "s1.e57"), o),
         r"s1\.e57: empty file \(0 bytes\)$"),
    # -- LAS/LAZ scans
    Case("LAS scan whose scale factor is NaN",
         lambda i, o, f: _extract(_las_scan(i / "s1.las", float("nan")), o),
         r"s1\.las: the header's scale factors must be finite and non-zero and its offsets "
         r"finite, got scales nan, 0\.0001, 0\.0001 and offsets 0, 0, 0: a corrupt header$"),
    Case("LAS scan whose scale factor is 0",
         lambda i, o, f: _extract(_las_scan(i / "s1.las", 0.0), o),
         r"s1\.las: the header's scale factors must be finite and non-zero .* got scales 0, "),
    Case("PLY named .las", lambda i, o, f: _extract(
        _write(i / "s1.las", _ply_head(1) + b"1 2 3\n"), o),
         r"s1\.las: cannot read as LAS/LAZ: Invalid file signature"),
    Case("empty LAZ scan", lambda i, o, f: _extract(_empty(i / "s1.laz"), o),
         r"s1\.laz: empty file \(0 bytes\)$"),
    Case("truncated LAZ scan", lambda i, o, f: _extract(
        _write(i / "s1.laz", AHN3.read_bytes()[: AHN3.stat().st_size // 2]), o),
         r"s1\.laz: corrupt or truncated point data after \d+ of 35231 points"),
    # -- camera files
    Case("empty camera file", lambda i, o, f: _camera_text(i, ""),
         r"camera\.json: empty camera file \(no JSON object\)$"),
    Case("truncated camera file",
         lambda i, o, f: _camera_text(i, '{"name": "test", "focal_mm": 10.0, "pixel_si'),
         r"camera\.json: invalid JSON at line 1, column 36: Unterminated string starting at "
         r"\(the file ends inside it: truncated\?\)$"),
    Case("camera file cut after a value", lambda i, o, f: _camera_text(
        i, '{"name": "test", "focal_mm": 10.0,\n "pixel_size_mm": 0.01,\n'),
         r"camera\.json: invalid JSON at line 3, column 1: Expecting property name enclosed in "
         r"double quotes \(the file ends inside it: truncated\?\)$"),
    Case("infinite focal length", lambda i, o, f: _camera_text(
        i, '{"name": "test", "focal_mm": 1e400, "pixel_size_mm": 0.01, "width_px": 1000, '
           '"height_px": 800}'),
         r"camera\.json: key 'focal_mm': must be finite, got inf$"),
    Case("camera file that is no text", lambda i, o, f: _camera_text(i, b"\xff\xd8\xff\xe0JFIF"),
         r"camera\.json: cannot read camera file: 'utf-8' codec can't decode byte 0xff"),
    # -- trajectory files: empty, truncated, values out of their physical range
    Case("empty trajectory", lambda i, o, f: _traj_file(i, ""),
         r"traj\.csv: the table is empty \(no header row\)$"),
    Case("truncated trajectory", lambda i, o, f: _traj_file(
        i, "image_id,time,group,easting,northing,height,roll,pitch,heading\n"
           "a,0,,85000,447500,500,0,0,0\nb,1,,85010,4475"),
         r"traj\.csv, row 3: has 5 values but the header has 9 columns$"),
    Case("time of 1e300", lambda i, o, f: _traj(i, ["a,0,,85000,447500,500,0,0,0",
                                               "b,1e300,,85010,447500,500,0,0,0"]),
         r"traj\.csv, row 3, column 'time': 1e\+300 s is beyond the plausible \+-1e\+10 s of a "
         r"time in seconds \(GPS week or standard time, UNIX time\): another unit, or not a "
         r"time$"),
    Case("times out of order", lambda i, o, f: _traj(i, [
        "a,100,L1,85000,447500,500,0,0,0", "b,101,L1,85010,447500,500,0,0,0",
        "c,50,L2,85000,447600,500,0,0,180", "d,100.5,L1,85020,447500,500,0,0,0"]),
         r"traj\.csv, row 5, column 'time': time 100\.5 s is earlier than 101 s in row 3 of "
         r"group 'L1': the rows are not in time order \(rows mixed up\? sort the table by "
         r"time\)$"),
    Case("height in millimetres", lambda i, o, f: _traj(i, ["a,0,,85000,447500,500000,0,0,0"]),
         r"traj\.csv, row 2, column 'height': 500000 m is outside the plausible heights -1000 "
         r"to 30000 m of a sensor \(a height in another unit\?\)$"),
    # -- TLS observation tables: distances from the scanner
    Case("negative range", lambda i, o, f: _tls_table(
        i, o, "range,hz_deg,vt_deg", ["-5.2,10,5", "6,20,5", "7,30,5"]),
         r"obs\.csv, row 2, column 'range': the range is -5\.2 m from the scanner: it must be "
         r"> 0$"),
    Case("target centre 1e300 m away", lambda i, o, f: _tls_table(
        i, o, "x,y,z", ["1,2,0.5", "1e300,1,1", "3,1,0.2"]),
         r"obs\.csv, row 3: the point is 1e\+300 m from the scanner, beyond the 10000 m a "
         r"terrestrial scanner reaches: another unit, or coordinates that are not in the "
         r"scanner's frame$"),
    # -- an adjustment that keeps its global test by rejecting what its model cannot explain
    Case("model error absorbed by data snooping", lambda i, o, f: _tls_args(
        *_cube(i, CYCLIC_ERROR), o),
         r"the TLS calibration failed its checks: data snooping rejected 2\d of 162 "
         r"observations \(1\d\.\d %\); its false alarms at alpha = 0\.001 explain at most 4 "
         r"\(0\.49 expected, P\(2\d or more\) = \d\.\de-\d\d\): a model that does not fit the "
         r"data \(parameters missing\?\) or many blunders, and the global test of the rest does "
         r"not show it\. No result was written \(the HTML report shows the failed adjustment\); "
         r"ACCEPT_DOUBTFUL writes them with a warning$", written=("report.html",)),
]  # fmt: skip


def _empty(path: Path) -> Path:
    path.write_bytes(b"")
    return path


def _write(path: Path, raw: bytes) -> Path:
    path.write_bytes(raw)
    return path


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_bad_input(case, tmp_path, capsys, monkeypatch, request):
    run_case(case, tmp_path, capsys, monkeypatch, request)


# ----------------------------------------------------------------------------- doubtful
def test_the_failed_report_says_why(tmp_path, capsys):
    """The run that failed its checks leaves the report of the failed adjustment, whose
    global test passed, saying that it passed only by rejecting what the model misses."""
    obs, control = _cube(tmp_path, CYCLIC_ERROR)
    assert main(_tls_args(obs, control, tmp_path)) == 2
    page = (tmp_path / "report.html").read_text(encoding="utf-8")
    assert '<div class="alarm">' in page and "The calibration FAILED its checks" in page
    assert "passed, but only after more rejections than false alarms explain" in page
    assert not (tmp_path / "stations.csv").exists()


def test_accepted_doubtful_calibration_says_so_in_every_output(tmp_path, capsys, caplog):
    obs, control = _cube(tmp_path, CYCLIC_ERROR)
    assert main(_tls_args(obs, control, tmp_path, "--accept-doubtful", "true")) == 0
    std = capsys.readouterr()
    assert std.out.startswith("WARNING: this calibration failed its checks and was written only "
                              "because ACCEPT_DOUBTFUL was set")  # fmt: skip
    assert "global test passed only after rejecting more observations than false alarms " \
           "explain (at most 4)" in std.out  # fmt: skip
    assert "explain at most 4" in caplog.text  # the log (stderr, QGIS's log)
    for name in ("stations.csv", "aps.csv", "v.csv"):
        lines = (tmp_path / name).read_text(encoding="utf-8").splitlines()
        assert lines[0].startswith("# WARNING: this calibration failed its checks"), name
        assert lines[1].startswith("# WARNING: data snooping rejected 2"), name
    page = (tmp_path / "report.html").read_text(encoding="utf-8")
    assert '<div class="alarm">' in page and "FAILED their checks" in page


@pytest.mark.parametrize(("extra", "blunders"), [({}, 0), ({}, 2)], ids=["clean", "2 blunders"])
def test_a_model_that_fits_is_not_flagged(tmp_path, capsys, extra, blunders):
    """The same network without the cyclic error (the paper's APs represent every error in
    it), with sigmas that fit the noise, clean or with two gross errors (which data snooping
    rejects, with this seed's one false alarm): the run passes."""
    obs, control = _cube(tmp_path, extra, seed=2, sigma_factor=1.0, blunders=blunders)
    assert main(_tls_args(obs, control, tmp_path)) == 0, capsys.readouterr().err
    std = capsys.readouterr().out
    assert "WARNING" not in std
    rejected = int(re.search(r"global test passed, (\d+) observations rejected", std)[1])
    assert blunders <= rejected <= 4  # the gross errors, and a false alarm or two at most
    assert not (tmp_path / "stations.csv").read_text(encoding="utf-8").startswith("#")


def test_the_bound_holds_its_false_alarm_rate():
    """Without a model error the rule fires at most with its level (0.001): never in 20
    simulated networks, whose rejections average the expected false alarms (0.49; the mean of
    20 Poisson counts is within 0.49 +- 3 x 0.16); with the model error planted it always
    fires. The bound itself is the binomial tail's (4: P(X > 4) = 1.8e-4, P(X > 3) = 1.9e-3,
    by scipy's binomial laws in the doctest of rejection_test)."""
    counts = []
    for seed in range(20):
        truth = paper_cube(grid=(3, 3))
        o, _ = observe(truth, *SCANNER_CLASSES["high_end"], rng=100 + seed)
        cal = calibrate(o, truth.control(), (), CalibrationOptions(levelled=False))
        test = rejection_test(cal.adjustment, cal.options.snooping_alpha)
        assert test.bound == 4 and test.passed, (seed, test)
        counts.append(test.rejected)
    assert abs(np.mean(counts) - 0.49) < 3 * np.sqrt(0.49 / 20), counts
    for seed in (1, 2, 3):
        truth = paper_cube(grid=(3, 3), aps={**PAPER_APS, **CYCLIC_ERROR})
        o, _ = observe(truth, *SCANNER_CLASSES["high_end"], rng=seed)
        cal = calibrate(o, truth.control(), (), CalibrationOptions(levelled=False))
        assert not rejection_test(cal.adjustment, cal.options.snooping_alpha).passed, seed


# ----------------------------------------------------------------------------- E57 forms
def test_e57_points_without_coordinates_are_left_out(tmp_path):
    """cartesianInvalidState 2 (no return): those points are not read as points at 0."""
    pye57 = pytest.importorskip("pye57")
    xyz = _points(500)
    state = np.zeros(500, dtype=np.int8)
    state[[0, 10, 499]] = 2
    e57 = pye57.E57(str(tmp_path / "s.e57"), mode="w")
    e57.write_scan_raw({"cartesianX": xyz[:, 0], "cartesianY": xyz[:, 1],
                        "cartesianZ": xyz[:, 2], "cartesianInvalidState": state})  # fmt: skip
    e57.close()
    got, _ = read_scan(tmp_path / "s.e57")
    assert got.shape == (497, 3)
    np.testing.assert_allclose(got, xyz[state == 0], atol=1e-6)  # E57's stored precision


def test_spherical_e57_is_converted_by_the_standards_formula(tmp_path, monkeypatch):
    """A scan stored as range, azimuth, elevation (pye57 writes Cartesian only, so its reader
    stands in): x = r cos(el) cos(az), y = r cos(el) sin(az), z = r sin(el) (ASTM E2807),
    the points of invalid state 1 (a direction only) left out."""
    pye57 = pytest.importorskip("pye57")
    xyz = _points(200)
    r = np.linalg.norm(xyz, axis=1)
    raw = {"sphericalRange": r, "sphericalAzimuth": np.arctan2(xyz[:, 1], xyz[:, 0]),
           "sphericalElevation": np.arcsin(xyz[:, 2] / r),
           "sphericalInvalidState": (np.arange(200) % 50 == 3).astype(np.int8)}  # fmt: skip

    class Spherical:
        scan_count = 1

        def __init__(self, path):
            pass

        def read_scan_raw(self, index, ignore_unsupported_fields=False):
            return raw

        def close(self):
            pass

    monkeypatch.setattr(pye57, "E57", Spherical)
    (tmp_path / "s.e57").write_bytes(b"x")
    got, intensity = read_scan(tmp_path / "s.e57")
    keep = raw["sphericalInvalidState"] == 0
    np.testing.assert_allclose(got, xyz[keep], atol=1e-12)
    assert got.shape == (196, 3) and np.isnan(intensity).all()
