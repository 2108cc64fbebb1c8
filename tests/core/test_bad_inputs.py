"""The catalogue of bad inputs: every case runs the command line (``lidarphoto.core.cli.main``)
and asserts the exact outcome: the exit code, one line on stderr with the error that names
the parameter or the file (row, column), nothing written (not even a temporary) unless the
case says what, and the input files unchanged. Stop signals run the command line in a
subprocess; stale temporaries, the adjustment's checks and the accuracy report's blunders
are at the end.
"""

from __future__ import annotations

import csv
import hashlib
import json
import os
import re
import signal
import struct
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import laspy
import numpy as np
import pytest
from lidarphoto.core.cli import main
from lidarphoto.core.io.atomic import remove_stale_temporaries
from lidarphoto.core.io.orientation import read_eo_csv
from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight

DATA = Path(__file__).resolve().parents[1] / "data"
AHN3 = DATA / "ahn3" / "ahn3_delft_crop60.laz"  # RD New + NAP (EPSG:7415), 60 m x 60 m
RD = "EPSG:28992"
FLIGHT = FlightConfig(
    n_buildings=12, n_planes=30, town_size_m=700.0, n_check=3, types=("tie", "line", "lcp")
)


# ----------------------------------------------------------------------------- inputs
@pytest.fixture(scope="module")
def flight(tmp_path_factory):
    """Inputs of a small simulated calibration flight over Delft (RD New), as files."""
    sim = simulate_flight(FLIGHT, seed=6)
    return sim, sim.write(tmp_path_factory.mktemp("flight"))


def _copy(src: Path, folder: Path, name: str | None = None) -> Path:
    dst = folder / (name or src.name)
    dst.write_bytes(src.read_bytes())
    return dst


def _edit_csv(path: Path, edit: Callable[[list[list[str]]], None]) -> Path:
    """Apply ``edit`` to the rows (header first) of a CSV file."""
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    edit(rows)
    with open(path, "w", newline="", encoding="utf-8") as fh:
        csv.writer(fh, lineterminator="\n").writerows(rows)
    return path


def _set(column: str, row: int, value: str) -> Callable[[list[list[str]]], None]:
    """An edit: the cell of data row ``row`` (0 = first after the header) in ``column``."""

    def edit(rows: list[list[str]]) -> None:
        rows[row + 1][rows[0].index(column)] = value

    return edit


def _las_with_count(folder: Path, count_change: int) -> Path:
    """The AHN3 crop as uncompressed LAS 1.2 whose header counts ``count_change`` more points
    than the file holds (negative: fewer)."""
    path = folder / "cloud.las"
    las = laspy.read(AHN3)
    las.write(path)
    raw = bytearray(path.read_bytes())
    raw[107:111] = struct.pack("<I", las.header.point_count + count_change)  # LAS 1.2 count
    path.write_bytes(bytes(raw))
    return path


def _camera(folder: Path, **changes) -> Path:
    cam = {"name": "test", "focal_mm": 10.0, "pixel_size_mm": 0.01, "width_px": 1000,
           "height_px": 800, **changes}  # fmt: skip
    path = folder / "camera.json"
    path.write_text(json.dumps(cam), encoding="utf-8")
    return path


def _monoplot_inputs(folder: Path, rows: list[str] | None = None) -> list[str]:
    """One nadir image 300 m above the AHN3 tile, its observations, camera and EO."""
    (folder / "eo.csv").write_text(
        "image_id,time,group,X,Y,Z,omega_deg,phi_deg,kappa_deg\n"
        "img,0,,84940,447595,300,0,0,0\n",
        encoding="utf-8",
    )
    rows = rows or ["img,p1,500,400,0.5,check,1", "img,p2,520,410,0.5,check,1"]
    (folder / "obs.csv").write_text(
        "image_id,point_id,col,row,sigma_px,type,target_id\n" + "\n".join(rows) + "\n",
        encoding="utf-8",
    )
    _camera(folder)
    return [
        "monoplot", "--observations", str(folder / "obs.csv"),
        "--camera", str(folder / "camera.json"), "--eo", str(folder / "eo.csv"),
        "--dsm", str(_copy(AHN3, folder)), "--crs", RD,
    ]  # fmt: skip


def _boresight_args(paths: dict[str, Path], folder: Path, out: Path) -> list[str]:
    """The boresight command on copies of the flight's files in ``folder``."""
    names = ("camera", "trajectory", "observations", "planes", "lines", "lcps")
    copy = {k: _copy(paths[k], folder) for k in names}
    return [
        "boresightcalibration", "--camera", str(copy["camera"]),
        "--trajectory", str(copy["trajectory"]), "--crs", RD,
        "--lever-arm", "0.15,-0.05,-0.6", "--observations", str(copy["observations"]),
        "--planes", str(copy["planes"]), "--lines", str(copy["lines"]),
        "--lcps", str(copy["lcps"]), "--snooping", "false",
        "--output-table", str(out / "boresight.csv"), "--output-eo", str(out / "eo.csv"),
        "--output-html", str(out / "summary.html"),
    ]  # fmt: skip


def _boresight_edited(paths: dict[str, Path], folder: Path, out: Path, name: str,
                      edit: Callable[[list[list[str]]], None]) -> list[str]:
    """The boresight command with the copy of input ``name`` edited."""
    argv = _boresight_args(paths, folder, out)
    _edit_csv(folder / paths[name].name, edit)
    return argv


# ----------------------------------------------------------------------------- the cases
@dataclass(frozen=True)
class Case:
    """A bad input: ``build(inp, out, flight_paths)`` writes the inputs and returns argv."""

    id: str
    build: Callable[[Path, Path, dict[str, Path]], list[str]]
    error: str  # regex searched in the one line on stderr
    code: int = 2
    written: tuple[str, ...] = ()  # output files that must exist despite the error
    patch: Callable[[pytest.MonkeyPatch], None] | None = None
    needs_flight: bool = False


def _ground(inp: Path, out: Path, *extra: str, src: Path | None = None) -> list[str]:
    cloud = src if src is not None else _copy(AHN3, inp)
    return ["groundfilter", "--input", str(cloud), "--output-cloud", str(out / "g.laz"), *extra]


def _low_memory(mp: pytest.MonkeyPatch) -> None:
    mp.setattr("lidarphoto.core.jobs.checks.available_memory", lambda: 100_000_000)


def _one_iteration(mp: pytest.MonkeyPatch) -> None:
    """The adjustment may iterate once only: it cannot converge."""
    import lidarphoto.core.photo.boresight as bs

    original = bs.calibrate

    def calibrate(*args, **kwargs):
        args = list(args)
        args[10] = replace(args[10], max_iterations=1)  # the BoresightOptions
        return original(*args, **kwargs)

    mp.setattr(bs, "calibrate", calibrate)


def _colmap(inp: Path, model: str = "OPENCV 1600 1200 1180 1180 800 600 -0.1 0 0 0",
            frame: tuple[str, ...] = ("--frame", "LOCAL"), binary: bool = False) -> list[str]:
    """A two-image COLMAP model in ``inp`` (text, or binary cut short) and its import argv."""
    if binary:
        cams = struct.pack("<QiiQQ", 1, 1, 0, 1600, 1200) + struct.pack("<3d", 1180, 800, 600)
        (inp / "cameras.bin").write_bytes(cams[:-4])
        (inp / "images.bin").write_bytes(struct.pack("<Q", 0))
        cameras = inp / "cameras.bin"
    else:
        cameras = inp / "cameras.txt"
        cameras.write_text(f"1 {model}\n", encoding="utf-8")
        (inp / "images.txt").write_text(
            "1 1 0 0 0 0 0 5 1 a.jpg\n800 600 -1\n2 1 0 0 0 1 0 5 1 b.jpg\n\n",
            encoding="utf-8",
        )  # fmt: skip
    return ["importcolmap", "--input", str(cameras), *frame,
            "--output-eo", str(inp.parent / "out" / "eo.csv")]  # fmt: skip


def _traj(inp: Path, rows: list[str], crs: str = RD) -> list[str]:
    path = inp / "traj.csv"
    path.write_text(
        "image_id,time,group,easting,northing,height,roll,pitch,heading\n"
        + "\n".join(rows) + "\n",
        encoding="utf-8",
    )  # fmt: skip
    return ["trajectorytoeo", "--input", str(path), "--crs", crs,
            "--output-csv", str(inp.parent / "out" / "eo.csv")]  # fmt: skip


CASES = [
    # -- parameters outside their physical range, named
    Case("cell size zero", lambda i, o, f: _ground(i, o, "--cell-size", "0"),
         r"CELL_SIZE: must be >= 0\.01, got 0$"),
    Case("slope beyond 10:1", lambda i, o, f: _ground(i, o, "--slope", "50"),
         r"SLOPE: must be <= 10 rise/run, got 50$"),
    Case("lever arm in millimetres", lambda i, o, f: _traj(i, ["a,0,,85000,447500,500,0,0,0"])
         + ["--lever-arm", "120,-50,-1350"],
         r"LEVER_ARM \(number 1 of 3\): must be <= 50, got 120$"),
    Case("boresight of 45 degrees", lambda i, o, f: _traj(i, ["a,0,,85000,447500,500,0,0,0"])
         + ["--boresight", "0,0,45"],
         r"BORESIGHT \(number 3 of 3\): must be <= 10 degrees, got 45$"),
    Case("INS sigma of zero",
         lambda i, o, f: _boresight_args(f, i, o) + ["--ins-grade", "custom", "--ins-sigmas",
                                                    "0,0.05,0.01,0.02"],
         r"INS_SIGMAS \(number 1 of 4\): must be >= 0\.0001, got 0$", needs_flight=True),
    Case("EO sigma negative", lambda i, o, f: _monoplot_inputs(i) + ["--eo-sigmas",
                                                                  "0.05,0.05,-1,0,0,0"],
         r"EO_SIGMAS \(number 3 of 6\): must be >= 0, got -1$"),
    Case("thresholds in the wrong order",
         lambda i, o, f: _ground(i, o, "--method", "pmf", "--initial-distance", "3",
                                 "--max-distance", "2"),
         r"INITIAL_DISTANCE \(3\) must not exceed MAX_DISTANCE \(2\)$"),
    Case("min support above K", lambda i, o, f: [
        "extractroofplanes", "--input", str(_copy(AHN3, i)), "--output-csv", str(o / "p.csv"),
        "--k-neighbours", "10", "--min-support", "12"],
         r"MIN_SUPPORT \(12\) must not exceed K_NEIGHBOURS \(10\)$"),
    # -- sizes against the data's extent and the free memory, with the figures
    Case("cell larger than the tile",
         lambda i, o, f: _ground(i, o, "--smrf-cell-size", "100", "--smrf-window", "100"),
         r"SMRF_CELL_SIZE: 100 metre is larger than the data's extent \(60 x 59\.99 metre\): "
         r"give a cell smaller than the extent$"),
    Case("window larger than the tile",
         lambda i, o, f: _ground(i, o, "--method", "pmf", "--max-window", "500"),
         r"MAX_WINDOW: 500 metre is more than twice the data's extent \(60 x 59\.99 metre\): "
         r"give about the size of the largest building$"),
    Case("grid too large for the memory",
         lambda i, o, f: _ground(i, o, "--smrf-cell-size", "0.02"),
         r"SMRF_CELL_SIZE 0\.02 metre: a grid of 3001 x 3000 cells over 60 x 59\.99 metre "
         r"needs about 723\.6 MB of memory; 100\.0 MB is free: give a larger cell$",
         patch=_low_memory),
    Case("a parameter of another method",
         lambda i, o, f: _ground(i, o, "--method", "csf", "--smrf-threshold", "0.5"),
         r"SMRF_THRESHOLD: parameter of another method than METHOD csf: set METHOD, or leave "
         r"it at the default$"),
    Case("RANSAC batch too large", lambda i, o, f: [
        "extractroofplanes", "--input", str(_copy(AHN3, i)), "--output-csv", str(o / "p.csv"),
        "--k-neighbours", "500", "--ransac-iterations", "1000"],
         r"K_NEIGHBOURS 500 with RANSAC_ITERATIONS 1000: one batch of 8192 points needs about "
         r"65\.5 GB of memory; 100\.0 MB is free", patch=_low_memory),
    Case("DSM cell larger than the tile",
         lambda i, o, f: _monoplot_inputs(i) + ["--dsm-crs", RD, "--cell-size", "80"],
         r"CELL_SIZE: 80 metre is larger than the data's extent \(60 x 59\.99 metre\)"),
    Case("line densified to 10^10 rays", lambda i, o, f: _monoplot_inputs(
        i, ["img,a,10,10,0.5,line,7", "img,b,990,790,0.5,line,7"])
         + ["--dsm-crs", RD, "--line-step", "1e-7"],
         r"LINE_STEP 1e-07 px: 12\d{9} rays needs about 12\.\d TB of memory"),
    # -- values in the files: finite, in range, on the image, once
    Case("NaN in the trajectory", lambda i, o, f: _traj(i, ["a,0,,85000,nan,500,0,0,0"]),
         r"traj\.csv, row 2, column 'northing': 'nan' is not a finite number$"),
    Case("pixel off the image", lambda i, o, f: _monoplot_inputs(
        i, ["img,p1,500,400,0.5,check,1", "img,p2,1200,400,0.5,check,1"]) + ["--dsm-crs", RD],
         r"obs\.csv, row 3, column 'col': 1200 px is off the image: the camera 'test' has "
         r"width_px 1000 \(pixels from 0 to 1000\); 1 row\(s\) affected$"),
    Case("observation row twice", lambda i, o, f: _monoplot_inputs(
        i, ["img,p1,500,400,0.5,check,1", "img,p2,501,400,0.5,check,1",
            "img,p1,500,400,0.5,check,1"]) + ["--dsm-crs", RD],
         r"obs\.csv, row 4: row 2 again \(point 'p1' of image 'img' at the same pixel\): a "
         r"duplicate row would count twice; remove one of them$"),
    Case("sigma_px in micrometres", lambda i, o, f: _monoplot_inputs(
        i, ["img,p1,500,400,450,check,1"]) + ["--dsm-crs", RD],
         r"obs\.csv, row 2, column 'sigma_px': sigma_px must be > 0 and <= 100 pixels, got "
         r"450$"),
    Case("focal length in pixels",
         lambda i, o, f: (_monoplot_inputs(i), _camera(i, focal_mm=10000.0))[0],
         r"camera\.json: key 'focal_mm': 10000 mm is outside the physical range 1 to 5000 mm"),
    Case("tie observation off the camera",
         lambda i, o, f: _boresight_edited(f, i, o, "observations", _set("row", 4, "-3")),
         r"observations\.csv, row 6, column 'row': -3 px is off the image: the camera "
         r"'UltraCam XP' has height_px 11310", needs_flight=True),
    Case("plane with a negative variance",
         lambda i, o, f: _boresight_edited(f, i, o, "planes", _set("cov_dd", 2, "-1e-4")),
         r"planes\.csv, row 4: the covariance of \(a, b, c, d\) is not positive semi-definite",
         needs_flight=True),
    Case("LCP id twice", lambda i, o, f: _boresight_edited(
        f, i, o, "lcps", lambda rows: rows.append(list(rows[1]))),
         r"lcps\.csv, row \d+, column 'id': id \d+ already appears in row 2$",
         needs_flight=True),
    # -- the CRS against the coordinates
    Case("trajectory in another country's CRS",
         lambda i, o, f: _traj(i, ["a,0,,85000,447500,500,0,0,0"], crs="EPSG:31983"),
         r"traj\.csv: the trajectory \(x 85000 to 85000, y 447500 to 447500 metre\) lies "
         r"outside the area of use of 'SIRGAS 2000 / UTM zone 23S'"),
    Case("trajectory in degrees", lambda i, o, f: _traj(i, ["a,0,,4.35,52.0,500,0,0,0",
                                                          "b,1,,4.36,52.01,500,0,0,0"]),
         r"\(x 4\.35 to 4\.36, y 52 to 52\.01\) looks like longitude and latitude in degrees, "
         r"not coordinates of 'Amersfoort / RD New' \(projected, metre\)$"),
    Case("cloud in another country's CRS",
         lambda i, o, f: _ground(i, o, "--crs", "EPSG:31983"),
         r"ahn3_delft_crop60\.laz: the cloud \(header extent\) \(x 84910\.001 to 84969\.999, y "
         r"447565 to 447624\.994 metre\) lies outside the area of use of 'SIRGAS 2000 / UTM zone "
         r"23S' \(Brazil - between 48°W and 42°W, northern and southern hemispheres, onshore and "
         r"offshore: longitude -48 to -42, latitude -33\.5 to 5\.13 deg; a corner maps to "
         r"longitude -88\.02, latitude -84\.55 deg\): wrong CRS, or coordinates in another unit "
         r"or axis order$"),
    Case("DSM whose geoid grid is missing", lambda i, o, f: _monoplot_inputs(i),
         r"the DSM in 'Amersfoort / RD New \+ NAP height' cannot be brought into the mapping "
         r"CRS 'Amersfoort / RD New': .* needs grid\(s\) not installed for PROJ: "
         r"nl_nsgi_nlgeo2018\.tif"),
    # -- LAS headers against the data
    Case("LAS header counts more points than the file holds",
         lambda i, o, f: _ground(i, o, "--crs", RD, src=_las_with_count(i, +1000)),
         r"cloud\.las: truncated: the file holds 35231 point records, the header says 36231$"),
    Case("LAS header counts fewer points than the file holds",
         lambda i, o, f: _ground(i, o, "--crs", RD, src=_las_with_count(i, -1000)),
         r"cloud\.las: the file holds 35231 point records but its header says 34231"),
    # -- outputs
    Case("output is the input", lambda i, o, f: [
        "groundfilter", "--input", str(_copy(AHN3, i)),
        "--output-cloud", str(i / "ahn3_delft_crop60.laz")],
         r"OUTPUT_CLOUD is the input INPUT .*: an output never overwrites an input"),
    Case("two outputs in one file",
         lambda i, o, f: _ground(i, o, "--output-dtm", str(o / "g.laz")),
         r"OUTPUT_CLOUD and OUTPUT_DTM are the same file"),
    Case("output under a file", lambda i, o, f: _ground(i, o)[:-1]
         + [str(_copy(AHN3, i, "plain.txt") / "g.laz")],
         r"OUTPUT_CLOUD: cannot write .*plain\.txt/g\.laz: .*plain\.txt is a file, not a "
         r"folder$"),
    Case("output is a folder", lambda i, o, f: _ground(i, o)[:-1] + [str(o)],
         r"OUTPUT_CLOUD: .*out is a folder; give a file name$"),
    # -- the adjustment's results
    Case("global test failed far beyond its bound", lambda i, o, f: _boresight_edited(
        f, i, o, "observations", lambda rows: [r.__setitem__(4, "0.01") for r in rows[1:]]),
         r"the boresight calibration failed its checks: .*the global test failed with sigma0 "
         r"= \d\d(\.\d)? > MAX_SIGMA0 3: the observations are \d\d(\.\d)? times less precise",
         written=("summary.html",), needs_flight=True),
    Case("implausible boresight", lambda i, o, f: _boresight_args(f, i, o)
         + ["--max-boresight", "0.05"],
         r"failed its checks: d_omega = 0\.07\d\d deg in group NE, d_phi = -0\.13\d\d deg in "
         r"group NE, .* beyond MAX_BORESIGHT 0\.05 deg", written=("summary.html",),
         needs_flight=True),
    Case("no convergence", lambda i, o, f: _boresight_args(f, i, o),
         r"failed its checks: the adjustment did not converge after 1 iterations \(no "
         r"convergence within 1 iterations\)", written=("summary.html",), patch=_one_iteration,
         needs_flight=True),
    # -- COLMAP: no frame, an unknown camera model, a truncated binary file
    Case("COLMAP model without a frame", lambda i, o, f: _colmap(i, frame=()),
         r"FRAME: a COLMAP model has no coordinate reference system; state its frame"),
    Case("COLMAP unknown camera model", lambda i, o, f: _colmap(i, "KANNALA 1600 1200 1 2 3"),
         r"cameras\.txt, row 1: camera 1: unknown COLMAP camera model 'KANNALA'"),
    Case("COLMAP FOV camera", lambda i, o, f: _colmap(i, "FOV 1600 1200 900 900 800 600 0.9"),
         r"camera 1: COLMAP camera model FOV is not supported"),
    Case("COLMAP truncated binary", lambda i, o, f: _colmap(i, binary=True),
         r"cameras\.bin: the file ends at byte \d+ inside a record \(truncated\?\)"),
]  # fmt: skip


def _snapshot(folder: Path) -> dict[str, str]:
    """Every file below ``folder`` (hidden ones too) with the SHA-256 of its content."""
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_bad_input(case, tmp_path, capsys, monkeypatch, request):
    paths = request.getfixturevalue("flight")[1] if case.needs_flight else {}
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    out.mkdir()
    argv = case.build(inp, out, paths)
    before = _snapshot(inp)
    if case.patch is not None:
        case.patch(monkeypatch)
    code = main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == case.code, err
    assert len(err) == 1, err
    assert err[0].startswith(f"lidarphoto {argv[0]}: error: "), err[0]
    assert re.search(case.error, err[0]), err[0]
    assert sorted(_snapshot(out)) == sorted(case.written)  # no output, no temporary
    assert _snapshot(inp) == before  # inputs untouched, nothing left beside them


# ----------------------------------------------------------------------------- signals
_SLOW_WRITER = """
import sys, time
from lidarphoto.core.io import pointcloud
from lidarphoto.core.cli import main

original = pointcloud.write_cloud

def slow(*args, **kwargs):  # the copy is under way, then it waits for the signal
    def progress(fraction):
        print("writing", flush=True)
        time.sleep(60)
    return original(*args, **{**kwargs, "progress": progress, "chunk_size": 5000})

pointcloud.write_cloud = slow
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.parametrize(
    ("signum", "code", "words"),
    [
        (signal.SIGTERM, 143, "stopped by SIGTERM; nothing was written"),
        (signal.SIGHUP, 129, "stopped by SIGHUP; nothing was written"),
        (signal.SIGINT, 130, "interrupted; nothing was written"),
    ],
    ids=["SIGTERM", "SIGHUP", "SIGINT"],
)
def test_stop_signal_removes_every_temporary(tmp_path, signum, code, words):
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    out.mkdir()
    old = out / "g.laz"
    old.write_bytes(b"the previous result")
    argv = _ground(inp, out, "--output-dtm", str(out / "dtm.tif"))
    before = _snapshot(inp)
    proc = subprocess.Popen(
        [sys.executable, "-W", "ignore", "-c", _SLOW_WRITER, *argv],  # (library warnings)
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert proc.stdout.readline().strip() == "writing"  # inside the write of the cloud
        temporaries = [p.name for p in out.iterdir() if p.name.startswith(".")]
        assert temporaries, "the writer's temporary should exist while it writes"
        proc.send_signal(signum)
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == code, err
    assert err.strip().splitlines() == [f"lidarphoto groundfilter: {words}"]
    assert sorted(p.name for p in out.iterdir()) == ["g.laz"]  # no temporary, no DTM
    assert old.read_bytes() == b"the previous result"
    assert _snapshot(inp) == before


# ----------------------------------------------------------------------------- stale files
def test_a_job_removes_its_stale_temporaries_only(tmp_path, capsys):
    """Temporaries a killed run (SIGKILL) left beside the outputs go when the job runs again;
    a fresh one (a writer still at work) and those of other files stay."""
    out = tmp_path / "out"
    out.mkdir()
    stale = [out / ".g.k3x9q1zz.part.laz", out / ".dtm.q8m2a7bb.part.tif",
             out / ".dtm.q8m2a7bb.part.tif.aux.xml"]  # fmt: skip
    keep = [out / ".g.fresh123.part.laz", out / ".notes.k3x9q1zz.part.laz",
            out / ".g.v.k3x9q1zz.part.laz"]  # fmt: skip
    hour_ago = time.time() - 3700
    for p in stale + keep:
        p.write_bytes(b"x")
        if p.name != ".g.fresh123.part.laz":
            os.utime(p, (hour_ago, hour_ago))
    argv = _ground(tmp_path, out, "--output-dtm", str(out / "dtm.tif"))
    assert main(argv) == 0, capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == sorted(["g.laz", "dtm.tif"]
                                                           + [p.name for p in keep])
    # the function itself, as the picking dock's autosave uses it
    target = tmp_path / "obs.csv"
    old = tmp_path / ".obs.a1b2c3d4.part.csv"
    old.write_text("")
    os.utime(old, (hour_ago, hour_ago))
    assert remove_stale_temporaries(target, older_than_s=3600) == [str(old)]
    assert remove_stale_temporaries(tmp_path / "missing" / "x.csv") == []


# ----------------------------------------------------------------------------- adjustment
def test_accepted_doubtful_calibration_says_so_in_every_output(flight, tmp_path, capsys, caplog):
    sim, paths = flight
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    argv = _boresight_args(paths, inp, out) + [
        "--max-boresight", "0.05", "--accept-doubtful", "true", "--residuals-csv",
        str(out / "residuals.csv"),
    ]  # fmt: skip
    assert main(argv) == 0
    std = capsys.readouterr()
    assert std.out.startswith("WARNING: this calibration failed its checks and was written only "
                              "because ACCEPT_DOUBTFUL was set")  # fmt: skip
    assert "beyond MAX_BORESIGHT 0.05 deg" in caplog.text  # the log (stderr, QGIS's log)
    for name in ("boresight.csv", "eo.csv", "residuals.csv"):
        lines = (out / name).read_text(encoding="utf-8").splitlines()
        assert lines[0].startswith("# WARNING: this calibration failed its checks"), name
        assert lines[1].startswith("# WARNING: d_omega = 0.07"), name
    page = (out / "summary.html").read_text(encoding="utf-8")
    assert '<div class="alarm">' in page and "FAILED their checks" in page
    eo = read_eo_csv(out / "eo.csv")  # the comment lines do not bother the readers
    assert eo.image_id == sim.trajectory.image_id


def test_the_failed_summary_shows_the_failed_adjustment(flight, tmp_path, capsys):
    _, paths = flight
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    assert main(_boresight_args(paths, inp, out) + ["--max-boresight", "0.05"]) == 2
    page = (out / "summary.html").read_text(encoding="utf-8")
    assert "The calibration FAILED its checks: no table and no exterior orientation" in page
    assert "beyond MAX_BORESIGHT 0.05 deg" in page and "<h2>Boresight</h2>" in page


# ----------------------------------------------------------------------------- accuracy
def test_gross_blunder_is_flagged_and_reported_with_and_without(tmp_path, capsys):
    """A check point 1000 km off (a typo in an easting): flagged by the robust screen, the
    report gives the figures with it (used, as asked) and without it, and NSSDA's exact
    radius copes with the extreme ratio of the axes."""
    rng = np.random.default_rng(0)  # no normal point beyond the robust threshold
    n = 25
    ref = np.column_stack([85000 + rng.uniform(0, 900, n), 447000 + rng.uniform(0, 900, n),
                           rng.uniform(0, 5, n)])  # fmt: skip
    meas = ref + rng.normal(0, [0.05, 0.05, 0.08], (n, 3))
    meas[7, 0] += 1e6
    table = tmp_path / "cp.csv"
    rows = ["id,e,n,h,e_ref,n_ref,h_ref"] + [
        f"P{k}," + ",".join(repr(float(v)) for v in (*m, *r))
        for k, (m, r) in enumerate(zip(meas, ref))
    ]
    table.write_text("\n".join(rows) + "\n", encoding="utf-8")
    out = tmp_path / "report.json"
    code = main(["accuracyreport", "--input", str(table), "--output-json", str(out),
                 "--output-html", str(tmp_path / "report.html")])  # fmt: skip
    std = capsys.readouterr()
    assert code == 0, std.err
    figures = json.loads(out.read_text(encoding="utf-8"))
    assert figures["outliers"]["flagged_ids"] == ["P7"]
    assert figures["rmse"]["RMSE_E"] == pytest.approx(1e6 / np.sqrt(n), rel=1e-3)
    clean = np.delete(meas - ref, 7, axis=0)
    assert figures["rmse_contrast"]["RMSE_E"] == pytest.approx(
        np.sqrt(np.mean(clean[:, 0] ** 2)), rel=1e-12
    )
    assert figures["rmse_contrast"]["RMSE_E"] < 0.1
    assert figures["contrast"]["name"] == "without the 1 flagged point(s)"
    assert "1 point(s) flagged as outliers (all points above); without the 1 flagged " in std.out
    nssda = next(r for r in figures["standards"] if r["key"] == "nssda")
    radius = nssda["figures"]["ACCURACY_HORIZONTAL_95"]
    assert radius == pytest.approx(1.96 * 1e6 / np.sqrt(n), rel=1e-3)
    page = (tmp_path / "report.html").read_text(encoding="utf-8")
    assert "For comparison: without the 1 flagged point(s) (24)" in page


def test_check_points_outside_their_crs_are_refused(tmp_path, capsys):
    table = tmp_path / "cp.csv"
    table.write_text("id,e,n,h,e_ref,n_ref,h_ref\nA,500000,7450000,5,500000.1,7450000,5\n"
                     "B,500100,7450000,5,500100,7450000.1,5\n", encoding="utf-8")  # fmt: skip
    out = tmp_path / "r.html"
    code = main(["accuracyreport", "--input", str(table), "--crs", RD, "--output-html", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and "the check points (x 500000 to 500100, y 7450000 to 7450000.1 " in err
    assert "outside the area of use of 'Amersfoort / RD New'" in err and not out.exists()
