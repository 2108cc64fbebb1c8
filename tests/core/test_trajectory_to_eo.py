"""Direct georeferencing against independent computations (pyproj Geod and Factors, SciPy)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.cli import main as cli_main
from lidarphoto.core.errors import CrsError, InputError
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.io.orientation import read_eo_csv
from lidarphoto.core.jobs import trajectory_to_eo
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.mount import MOUNT_PRESETS
from pyproj import Geod, Proj
from scipy.spatial.transform import Rotation

CRS = "EPSG:31983"  # SIRGAS 2000 / UTM 23S, GRS80
GEOD = Geod(ellps="GRS80")
SAMPLE = Path(__file__).resolve().parents[2] / "sample_data" / "trajectory_demo.csv"
HEADER = "image_id,time,group,easting,northing,height,roll,pitch,heading\n"


def run_trajectory_to_eo(path, crs, output_csv=None, **params):
    """The trajectorytoeo job on a file; returns its EO table."""
    raw = {"INPUT": str(path), "CRS": crs, "OUTPUT_CSV": output_csv}
    raw.update({k.upper(): v for k, v in params.items()})
    return run_job(trajectory_to_eo, raw).data


def _write(tmp_path: Path, rows: list[str], header: str = HEADER, name: str = "traj.csv") -> Path:
    path = tmp_path / name
    path.write_text(header + "".join(r + "\n" for r in rows), encoding="utf-8")
    return path


def _true_north_grid_azimuth(e: float, n: float) -> float:
    frame = MappingFrame.from_user_input(CRS)
    lat, lon, _ = frame.map_to_geodetic(np.array([[e, n, 0.0]]))[0]
    conv = Proj(frame.crs).get_factors(lon, lat).meridian_convergence
    return -np.radians(conv)  # PROJ's sign is opposite to the clockwise grid azimuth


def _wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


@pytest.mark.parametrize("heading", [0.0, 37.0, 90.0, 225.0])
def test_level_flight_kappa_is_heading_plus_convergence(tmp_path, heading):
    e, n = 386000.0, 7530000.0
    path = _write(tmp_path, [f"a,1.0,L1,{e},{n},2400,0,0,{heading}"])
    eo = run_trajectory_to_eo(path, CRS)
    theta = _true_north_grid_azimuth(e, n)
    np.testing.assert_allclose(eo.opk[0, :2], 0.0, atol=1e-12)
    # image top = forward: its grid azimuth is heading + theta, and kappa turns the other way
    assert _wrap(eo.opk[0, 2] + np.radians(heading) + theta) == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_allclose(eo.xyz[0], [e, n, 2400.0], atol=1e-8)


def test_image_right_forward_flying_east_is_north_up(tmp_path):
    e, n = 420000.0, 7550000.0
    path = _write(tmp_path, [f"a,,,{e},{n},2400,0,0,90"])
    eo = run_trajectory_to_eo(path, CRS, mount="image_right_forward")
    theta = _true_north_grid_azimuth(e, n)
    assert _wrap(eo.opk[0, 2] + theta) == pytest.approx(0.0, abs=1e-9)
    assert np.isnan(eo.time[0])


@pytest.mark.parametrize("heading", [0.0, 128.0, 301.0])
def test_horizontal_lever_arm_against_geodesic(tmp_path, heading):
    e, n, h = 395000.0, 7545000.0, 2400.0
    path = _write(tmp_path, [f"a,0,,{e},{n},{h},0,0,{heading}"])
    eo = run_trajectory_to_eo(path, CRS, lever_arm="10,0,0")
    frame = MappingFrame.from_user_input(CRS)
    lat, lon, _ = frame.map_to_geodetic(np.array([[e, n, h]]))[0]
    lon2, lat2, _ = GEOD.fwd(lon, lat, heading, 10.0)
    expected = frame.geodetic_to_map(np.array([[lat2, lon2, h]]))[0]
    # a 10 m chord and the geodesic differ by ~1e-10 m horizontally and L^2/2R ~ 8e-6 m in height
    np.testing.assert_allclose(eo.xyz[0, :2], expected[:2], atol=1e-6)
    assert eo.xyz[0, 2] == pytest.approx(h + 10.0**2 / (2 * 6.37e6), abs=2e-6)


def test_vertical_lever_arm_with_roll(tmp_path):
    e, n, h = 395000.0, 7545000.0, 2400.0
    path = _write(tmp_path, [f"a,0,,{e},{n},{h},30,0,0"])
    eo = run_trajectory_to_eo(path, CRS, lever_arm="0,0,-2")
    frame = MappingFrame.from_user_input(CRS)
    lat, lon, _ = frame.map_to_geodetic(np.array([[e, n, h]]))[0]
    # 2 m up the body z axis rolled 30 deg right wing down: 1 m east, sqrt(3) m up
    lon2, lat2, _ = GEOD.fwd(lon, lat, 90.0, 1.0)
    expected = frame.geodetic_to_map(np.array([[lat2, lon2, h + np.sqrt(3.0)]]))[0]
    np.testing.assert_allclose(eo.xyz[0], expected, atol=1e-6)


def test_attitude_chain_against_scipy(tmp_path):
    rng = np.random.default_rng(3)
    rows, truth = [], []
    e, n = 401000.0, 7541000.0
    bore = np.array([0.4, -0.3, 1.1])  # degrees
    for i in range(20):
        r, p, h = rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(0, 360)
        rows.append(f"i{i},{i},,{e},{n},2400,{r},{p},{h}")
        theta = _true_north_grid_azimuth(e, n)
        r_b_n = Rotation.from_euler("ZYX", [h, p, r], degrees=True)
        nominal = Rotation.from_matrix(MOUNT_PRESETS["image_bottom_forward"])
        d_r = Rotation.from_euler("XYZ", bore, degrees=True)
        ned_to_enu = Rotation.from_matrix([[0, 1, 0], [1, 0, 0], [0, 0, -1]])
        to_grid = Rotation.from_euler("Z", -theta)  # grid azimuth = true azimuth + theta
        r_c_m = to_grid * ned_to_enu * r_b_n * nominal * d_r
        truth.append(r_c_m.as_euler("XYZ"))  # R_c^m = Rx(w) Ry(p) Rz(k)
    path = _write(tmp_path, rows)
    eo = run_trajectory_to_eo(
        path, CRS, mount="image_bottom_forward", boresight=",".join(map(str, bore))
    )
    np.testing.assert_allclose(_wrap(eo.opk - np.array(truth)), 0.0, atol=1e-10)


def test_geographic_and_projected_input_agree(tmp_path):
    frame = MappingFrame.from_user_input(CRS)
    llh = frame.map_to_geodetic(np.array([[402000.0, 7541000.0, 2427.3]]))[0]
    a = _write(tmp_path, ["x,5,S,402000,7541000,2427.3,1.2,-0.7,224.8"], name="a.csv")
    b = _write(
        tmp_path,
        [f"x,5,S,{float(llh[0])!r},{float(llh[1])!r},2427.3,1.2,-0.7,224.8"],
        header="image_id,time,group,latitude,longitude,height,roll,pitch,heading\n",
        name="b.csv",
    )
    kw = {"lever_arm": "0.2,-0.1,-1.5", "boresight": "0.01,0.02,-0.03"}
    ea, eb = run_trajectory_to_eo(a, CRS, **kw), run_trajectory_to_eo(b, CRS, **kw)
    np.testing.assert_allclose(ea.xyz, eb.xyz, atol=1e-7)
    np.testing.assert_allclose(ea.opk, eb.opk, atol=1e-12)


def test_csv_round_trip_and_sample(tmp_path):
    out = tmp_path / "sub" / "eo.csv"
    eo = run_trajectory_to_eo(SAMPLE, CRS, lever_arm="0.1,0.05,-1.2", output_csv=out)
    back = read_eo_csv(out)
    assert back.image_id == eo.image_id and back.group == eo.group
    np.testing.assert_allclose(back.xyz, eo.xyz, atol=6e-5)
    np.testing.assert_allclose(back.opk, eo.opk, atol=1e-11)
    np.testing.assert_allclose(back.time, eo.time)
    assert not [p for p in out.parent.iterdir() if p.name != "eo.csv"]  # no temp files left


@pytest.mark.parametrize(
    ("rows", "header", "words"),
    [
        (["a,0,,1,2,3,0,0,0", "a,1,,1,2,3,0,0,0"], HEADER, "row 3.*'image_id'.*already"),
        (["a,0,,1,two,3,0,0,0"], HEADER, "row 2.*'northing'.*'two' is not a number"),
        (["a,0,,1,2,3,0,95,0"], HEADER, "row 2.*'pitch'.*outside"),
        (["a,0,,1,2,3,0,0"], HEADER, "row 2.*8 values.*9 columns"),
        ([], HEADER, "no data rows"),
        (["a,0,1,2,3,0,0,0"], "image_id,time,easting,height,roll,pitch,heading,x2\n", "northing"),
        (["a,0,1,2,3,0,0"], "image_id,time,foo,bar,height,roll,pitch\n", "easting/northing"),
        (["a,0,,1,2,nan,0,0,0"], HEADER, "'height'.*not a finite"),
    ],
)
def test_bad_trajectory_names_row_and_column(tmp_path, rows, header, words):
    path = _write(tmp_path, rows, header=header)
    out = tmp_path / "eo.csv"
    with pytest.raises(InputError, match=words):
        run_trajectory_to_eo(path, CRS, output_csv=out)
    assert not out.exists()


@pytest.mark.parametrize(
    ("kwargs", "error", "words"),
    [
        ({"mount": "sideways"}, InputError, "MOUNT: 'sideways' is not one of"),
        ({"mount": "custom", "mount_matrix": "1,0,0,0,1,0,0,0,-1"}, InputError, "not a rotation"),
        ({"mount": "custom", "mount_matrix": "1,0,0,0,1,0,0,0,2"}, InputError,
         r"MOUNT_MATRIX \(number 9 of 9\): must be <= 1, got 2"),
        ({"lever_arm": "0,0,1350"}, InputError, r"LEVER_ARM \(number 3 of 3\): must be <= 50"),
        ({"boresight": "0,0,45"}, InputError, r"BORESIGHT \(number 3 of 3\): must be <= 10"),
        ({"mount": "custom", "mount_matrix": ""}, InputError, "needs MOUNT_MATRIX: 9 numbers"),
        ({"boresight": "1,2"}, InputError, "BORESIGHT: expected 3 numbers"),
        ({"lever_arm": "1,x,3"}, InputError, "LEVER_ARM"),
        ({"crs": "EPSG:4326"}, CrsError, "projected"),
    ],
)
def test_bad_parameters(tmp_path, kwargs, error, words):
    args = {"crs": CRS, **kwargs}
    with pytest.raises(error, match=words):
        run_trajectory_to_eo(SAMPLE, **args)


def test_missing_file():
    with pytest.raises(InputError, match="not found"):
        run_trajectory_to_eo("/nonexistent/traj.csv", CRS)


def test_custom_mount_equals_preset(tmp_path):
    matrix = ",".join(str(v) for v in MOUNT_PRESETS["image_left_forward"].ravel())
    a = run_trajectory_to_eo(SAMPLE, CRS, mount="custom", mount_matrix=matrix)
    b = run_trajectory_to_eo(SAMPLE, CRS, mount="image_left_forward")
    c = run_trajectory_to_eo(SAMPLE, CRS, mount="3")  # the QGIS enum index
    np.testing.assert_allclose(a.opk, b.opk, atol=1e-15)
    np.testing.assert_allclose(c.opk, b.opk, atol=1e-15)


def test_cli(tmp_path, capsys):
    out = tmp_path / "eo.csv"
    rc = cli_main(
        ["trajectorytoeo", "--input", str(SAMPLE), "--crs", CRS, "--output-csv", str(out)]
    )
    assert rc == 0 and len(read_eo_csv(out)) == 6
    rc = cli_main(["trajectorytoeo", "--input", str(SAMPLE), "--crs", "EPSG:4326"])
    assert rc == 2 and "must be projected" in capsys.readouterr().err


def test_python_m_entry_point():
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "lidarphoto",
            "trajectorytoeo",
            "--input",
            str(SAMPLE),
            "--crs",
            CRS,
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[0].startswith("image_id,time,group,X,Y,Z")
    assert len(r.stdout.splitlines()) == 7
