"""Trajectory import against analytic truth: a simulated 200 Hz flight (heading through north,
a +-20 degree roll manoeuvre, a drifting wander angle, exact velocities) written as a real
SBET, as an ASCII export and as a generic CSV, interpolated at times between the records;
the time systems; the sign of the timing offset; refusals by name with nothing written."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.frames import MappingFrame, ned_to_ecef_rotation
from lidarphoto.core.geometry.rotations import rph_to_matrix
from lidarphoto.core.io.camera_events import read_camera_events
from lidarphoto.core.io.navigation_text import read_nav_ascii, read_nav_csv
from lidarphoto.core.io.orientation import read_eo_csv
from lidarphoto.core.io.sbet import read_sbet, sbet_records, write_sbet
from lidarphoto.core.io.trajectory import read_trajectory_csv
from lidarphoto.core.jobs import import_trajectory, trajectory_to_eo
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.navigation import CameraEvents, gps_seconds_of_week
from lidarphoto.core.photo.navigation import interpolate_trajectory as interpolate
from lidarphoto.core.photo.trajectory_options import TrajectoryImportOptions
from lidarphoto.core.simulation.navigation import SimulatedFlight
from scipy.spatial.transform import Rotation

CRS = "EPSG:31983"  # SIRGAS 2000 / UTM 23S
FRAME = MappingFrame.from_user_input(CRS)
SIM = SimulatedFlight(FRAME)
RATE_HZ = 200.0
DURATION_S = 12.0  # the heading passes north at ~5 s, the roll manoeuvre peaks at 3.75 s
TIMES = SIM.t0 + np.arange(int(DURATION_S * RATE_HZ) + 1) / RATE_HZ
# off-record times: never on a record, spread over the whole flight
EVENT_TIMES = SIM.t0 + 0.05 + np.arange(60) * 0.1987 + 0.00123
POS_TOL_M, ATT_TOL_DEG = 1e-3, 2e-4


@pytest.fixture(scope="module")
def records():
    return SIM.records(TIMES)


def _sbet(path, rec):
    llh_rad = np.column_stack([np.radians(rec["llh"][:, :2]), rec["llh"][:, 2]])
    write_sbet(path, sbet_records(rec["time"], llh_rad, rec["v_ned"], rec["rph"], rec["wander"]))
    return path


def _events(times, names=None, rows=None):
    names = names or tuple(f"IMG_{k:04d}" for k in range(len(times)))
    return CameraEvents(names, np.asarray(times), ("",) * len(times),
                        rows or tuple(range(2, len(times) + 2)), "events.csv")  # fmt: skip


def _errors(traj, times):
    """Largest position error (m, in the map) and attitude error (degrees) against truth."""
    xyz, _ = SIM.position(times)
    pos = np.linalg.norm(traj.position - FRAME.ecef_to_map(xyz), axis=1).max()
    r_true = Rotation.from_matrix(rph_to_matrix(*SIM.attitude(times).T))
    r_got = Rotation.from_matrix(rph_to_matrix(*traj.rph.T))
    return pos, np.degrees((r_true.inv() * r_got).magnitude()).max()


def test_sbet_interpolated_between_records_within_1_mm_and_0_0002_deg(tmp_path, records):
    nav = read_sbet(_sbet(tmp_path / "sbet_sim.out", records))
    assert len(nav) == len(TIMES) and (tmp_path / "sbet_sim.out").stat().st_size == 136 * len(TIMES)
    traj = interpolate(nav, _events(EVENT_TIMES), FRAME, TrajectoryImportOptions())
    pos, att = _errors(traj, EVENT_TIMES)
    assert pos < POS_TOL_M and att < ATT_TOL_DEG, (pos, att)
    # the heading crossed north within the events, and is reported in [0, 360)
    h = np.degrees(traj.rph[:, 2])
    assert (h > 350).any() and (h < 10).any() and (h >= 0).all() and (h < 360).all()
    # and a linear interpolation of the angles would have failed there (the trap itself)
    assert np.ptp(np.degrees(SIM.attitude(TIMES)[:, 2])) > 300


def test_at_10_hz_the_cubic_attitude_holds_the_tolerance_and_slerp_does_not(tmp_path, records):
    """SLERP assumes a constant angular velocity: the roll manoeuvre's acceleration (3.5
    deg/s^2) costs it alpha h^2 / 8 = 0.0044 deg at 10 Hz; the cubic stays within 0.0002."""
    ten_hz = {k: v[::20] for k, v in records.items()}
    nav = read_sbet(_sbet(tmp_path / "s10.out", ten_hz))
    events = _events(EVENT_TIMES)
    cubic = interpolate(nav, events, FRAME, TrajectoryImportOptions(max_gap_s=0.11))
    slerp = interpolate(nav, events, FRAME, TrajectoryImportOptions(max_gap_s=0.11,
                                                                    attitude="slerp"))  # fmt: skip
    pos, att = _errors(cubic, EVENT_TIMES)
    assert pos < POS_TOL_M and att < ATT_TOL_DEG, (pos, att)
    assert 0.001 < _errors(slerp, EVENT_TIMES)[1] < 0.0044 * 1.5


def test_the_wander_angle_is_taken_off_the_platform_heading(tmp_path, records):
    raw = np.fromfile(_sbet(tmp_path / "w.out", records), dtype="<f8").reshape(-1, 17)
    assert np.abs(raw[:, 10]).max() > 0.1  # the file's headings are wander-frame headings
    np.testing.assert_allclose(np.mod(raw[:, 9] - raw[:, 10], 2 * np.pi), records["rph"][:, 2],
                               atol=1e-12)  # fmt: skip
    nav = read_sbet(tmp_path / "w.out")
    np.testing.assert_allclose(nav.rph[:, 2], records["rph"][:, 2], atol=1e-12)
    np.testing.assert_allclose(nav.velocity_ned, records["v_ned"], atol=1e-9)


def _ascii_export(path, rec, comma=False):
    names = ["GPSTime", "Latitude", "Longitude", "H-Ell", "Roll", "Pitch", "Heading", "VNorth",
             "VEast", "VUp"]  # fmt: skip
    units = ["(sec)", "(deg)", "(deg)", "(m)", "(deg)", "(deg)", "(deg)", "(m/s)", "(m/s)",
             "(m/s)"]  # fmt: skip
    if not comma:  # Inertial Explorer style: a date and a clock time as text, not used
        names, units = ["Date", "UTCTime", *names], ["(YMD)", "(HMS)", *units]
    sep = ", " if comma else "  "
    lines = ["Project: simulated flight", "Datum: SIRGAS 2000", "-" * 40, sep.join(names),
             sep.join(units)]  # fmt: skip
    deg = np.degrees(rec["rph"])
    for k in range(len(rec["time"])):
        v = rec["v_ned"][k]
        row = (rec["time"][k], *rec["llh"][k], *deg[k], v[0], v[1], -v[2])
        text = [repr(float(x)) for x in row]
        lines.append(sep.join(text if comma else ["1997/01/15", "06:13:13.00", *text]))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


@pytest.mark.parametrize("comma", [False, True])
def test_ascii_export_interpolated_within_tolerance(tmp_path, records, comma):
    nav = read_nav_ascii(_ascii_export(tmp_path / "export.txt", records, comma))
    assert nav.velocity_ned is not None and nav.numbers[0] == 6  # after 5 lines of header
    traj = interpolate(nav, _events(EVENT_TIMES), FRAME, TrajectoryImportOptions())
    pos, att = _errors(traj, EVENT_TIMES)
    assert pos < POS_TOL_M and att < ATT_TOL_DEG, (pos, att)


def test_generic_csv_without_velocities_in_map_coordinates(tmp_path, records):
    """At 200 Hz and at 50 Hz, eastings/northings, no velocities (three-point differences)."""
    enh = FRAME.geodetic_to_map(records["llh"])
    deg = np.degrees(records["rph"])
    for step in (1, 4):
        rows = ["time,easting,northing,height,roll,pitch,heading"] + [
            ",".join(repr(float(x)) for x in (records["time"][k], *enh[k], *deg[k]))
            for k in range(0, len(TIMES), step)
        ]
        path = tmp_path / f"nav_{step}.csv"
        path.write_text("\n".join(rows) + "\n", encoding="utf-8")
        nav = read_nav_csv(path)
        assert nav.velocity_ned is None and not nav.geodetic
        traj = interpolate(nav, _events(EVENT_TIMES), FRAME, TrajectoryImportOptions())
        pos, att = _errors(traj, EVENT_TIMES)
        assert pos < POS_TOL_M and att < ATT_TOL_DEG, (step, pos, att)


def test_utc_events_with_leap_seconds_and_gps_week():
    # week 1930 began on Sunday 2017-01-01 00:00:00 GPS; GPS - UTC was 17 s before, 18 after
    utc = dt.timezone.utc
    assert gps_seconds_of_week(dt.datetime(2017, 1, 1, tzinfo=utc), 18) == 18.0
    assert gps_seconds_of_week(dt.datetime(2016, 12, 31, 23, 59, 50, tzinfo=utc), 17) == 7.0
    # 2026-12-02 is a Wednesday: 3 days + 06:13:13.123456 + 18 s into the week
    t = gps_seconds_of_week(dt.datetime(2026, 12, 2, 6, 13, 13, 123456, tzinfo=utc), 18)
    assert t == pytest.approx(3 * 86400 + 6 * 3600 + 13 * 60 + 13.123456 + 18, abs=1e-9)


def test_event_file_in_utc_equals_the_same_events_in_gps_seconds(tmp_path):
    (tmp_path / "utc.csv").write_text(
        "image_id,time\na,2026-12-02T06:13:13.1234Z\nb,2026-12-02T03:13:13.5-03:00\n"
    )
    (tmp_path / "gps.csv").write_text("image_id,time\na,281611.1234\nb,281611.5\n")
    u = read_camera_events(tmp_path / "utc.csv", "utc", 18)
    g = read_camera_events(tmp_path / "gps.csv", "gps")
    np.testing.assert_allclose(u.time, g.time, atol=1e-9)


def test_events_either_side_of_the_week_end_match_a_trajectory_through_it(tmp_path, records):
    """The SBET's clock runs past 604800 s at the week's end; events start again at 0."""
    shift = 604800.0 - 5.0 - SIM.t0  # the week ends 5 s into the flight
    moved = dict(records, time=records["time"] + shift)
    nav = read_sbet(_sbet(tmp_path / "week.out", moved))
    sow = np.mod(EVENT_TIMES + shift, 604800.0)
    assert sow.min() < 10 and sow.max() > 604790
    traj = interpolate(nav, _events(sow), FRAME, TrajectoryImportOptions())
    pos, att = _errors(traj, EVENT_TIMES)
    assert pos < POS_TOL_M and att < ATT_TOL_DEG


def test_timing_offset_sign_trajectory_time_is_event_time_plus_offset(tmp_path, records):
    nav = read_sbet(_sbet(tmp_path / "o.out", records))
    offset = 0.0123
    camera_clock = EVENT_TIMES - offset  # the camera's clock is 12.3 ms behind
    traj = interpolate(nav, _events(camera_clock), FRAME,
                       TrajectoryImportOptions(time_offset_s=offset))  # fmt: skip
    np.testing.assert_allclose(traj.time, EVENT_TIMES, atol=1e-9)
    pos, _ = _errors(traj, EVENT_TIMES)
    assert pos < POS_TOL_M
    wrong = interpolate(nav, _events(camera_clock), FRAME,
                        TrajectoryImportOptions(time_offset_s=-offset))  # fmt: skip
    assert _errors(wrong, EVENT_TIMES)[0] > 1.0  # 24.6 ms at 60 m/s: 1.5 m


def test_truncated_sbet_is_refused_by_name(tmp_path, records):
    path = _sbet(tmp_path / "cut.out", records)
    data = path.read_bytes()
    path.write_bytes(data[:-50])
    with pytest.raises(InputError, match=r"cut\.out: .*not a whole number of 136-byte SBET "
                       r"records \(2400 records and 86 bytes\)"):  # fmt: skip
        read_sbet(path)


def test_sbet_records_out_of_order_are_refused_with_the_record(tmp_path, records):
    rec = dict(records, time=records["time"].copy())
    rec["time"][10] = rec["time"][9]
    with pytest.raises(InputError, match=r"record 11 \(byte 1360\): time .* not later"):
        read_sbet(_sbet(tmp_path / "dup.out", rec))


def test_events_outside_and_in_a_gap_are_refused_by_name(tmp_path, records):
    nav = read_sbet(_sbet(tmp_path / "t.out", records))
    late = _events([EVENT_TIMES[0], TIMES[-1] + 0.5], names=("a", "late"), rows=(2, 3))
    with pytest.raises(InputError, match=r"events\.csv, row 3: image 'late' .* outside the "
                       r"trajectory .*t\.out"):  # fmt: skip
        interpolate(nav, late, FRAME, TrajectoryImportOptions())
    keep = np.ones(len(TIMES), bool)
    keep[1000:1040] = False  # 0.2 s without records
    cut = {k: v[keep] for k, v in records.items()}
    nav = read_sbet(_sbet(tmp_path / "gap.out", cut))
    inside = _events([TIMES[1020]], names=("g",), rows=(7,))
    with pytest.raises(InputError, match=r"row 7: image 'g' .* gap of 0\.205 s .*between "
                       r"records 1000 and 1001.* MAX_GAP = 0\.1 s"):  # fmt: skip
        interpolate(nav, inside, FRAME, TrajectoryImportOptions())
    traj = interpolate(nav, inside, FRAME, TrajectoryImportOptions(max_gap_s=0.25))
    assert len(traj) == 1


def test_velocities_in_another_convention_are_refused(tmp_path, records):
    rec = dict(records, v_ned=records["v_ned"] * np.array([1.0, -1.0, 1.0]))  # east flipped
    nav = read_sbet(_sbet(tmp_path / "v.out", rec))
    with pytest.raises(InputError, match=r"v\.out: the velocities of records .* another frame"):
        interpolate(nav, _events(EVENT_TIMES[:3]), FRAME, TrajectoryImportOptions())


def _run(tmp_path, records, events_text, **params):
    sbet = _sbet(tmp_path / "job.out", records)
    events = tmp_path / "events.csv"
    events.write_text(events_text, encoding="utf-8")
    raw = {
        "INPUT": str(sbet),
        "EVENTS": str(events),
        "CRS": CRS,
        "OUTPUT_TRAJECTORY": str(tmp_path / "traj.csv"),
        "OUTPUT_EO": str(tmp_path / "eo.csv"),
    }
    raw.update({k.upper(): v for k, v in params.items()})  # fmt: skip
    return run_job(import_trajectory, raw)


def test_job_writes_the_trajectory_table_trajectorytoeo_reads(tmp_path, records):
    rows = "".join(f"IMG_{k},{float(t)!r},L1\n" for k, t in enumerate(EVENT_TIMES[:8]))
    result = _run(tmp_path, records, "image_id,time,group\n" + rows, lever_arm="0.2,0,-0.1",
                  mount="image_right_forward")  # fmt: skip
    assert result.results == {"IMAGE_COUNT": 8, "RECORD_COUNT": len(TIMES)}
    traj = read_trajectory_csv(tmp_path / "traj.csv")
    assert traj.image_id[0] == "IMG_0" and traj.group[0] == "L1"
    xyz, _ = SIM.position(EVENT_TIMES[:8])
    assert np.abs(traj.position - FRAME.ecef_to_map(xyz)).max() < POS_TOL_M
    # its EO equals trajectorytoeo's on the written table (same mount, same science)
    eo = read_eo_csv(tmp_path / "eo.csv")
    again = run_job(trajectory_to_eo, {"INPUT": str(tmp_path / "traj.csv"), "CRS": CRS,
                                       "LEVER_ARM": "0.2,0,-0.1",
                                       "MOUNT": "image_right_forward"}).data  # fmt: skip
    np.testing.assert_allclose(eo.xyz, again.xyz, atol=1e-6)
    np.testing.assert_allclose(eo.opk, again.opk, atol=1e-9)


def _true_velocity_ned(times):
    xyz, v = SIM.position(times)
    llh = FRAME.ecef_to_geodetic(xyz)
    return np.einsum("kji,kj->ki", ned_to_ecef_rotation(llh[:, 0], llh[:, 1]), v)


def test_velocity_at_the_events_is_written_and_read_back(tmp_path, records):
    """The exposure's velocity (the Hermite's derivative; boresightcalibration's timing offset
    uses it) against the analytic truth: 7e-7 m/s from the 200 Hz SBET's velocities, 7e-6
    m/s (200 Hz) and 1e-4 m/s (50 Hz) from a CSV's positions alone (measured; ~60 m/s)."""
    rows = "".join(f"IMG_{k},{float(t)!r},L1\n" for k, t in enumerate(EVENT_TIMES))
    _run(tmp_path, records, "image_id,time,group\n" + rows)
    header = (tmp_path / "traj.csv").read_text(encoding="utf-8").splitlines()[0].split(",")
    assert header[-3:] == ["v_north", "v_east", "v_up"]
    traj = read_trajectory_csv(tmp_path / "traj.csv")
    truth = _true_velocity_ned(EVENT_TIMES)
    assert np.abs(traj.velocity_ned - truth).max() < 1e-5
    enh, deg = FRAME.geodetic_to_map(records["llh"]), np.degrees(records["rph"])
    for step, tol in ((1, 1e-4), (4, 1e-3)):
        lines = ["time,easting,northing,height,roll,pitch,heading"] + [
            ",".join(repr(float(x)) for x in (records["time"][k], *enh[k], *deg[k]))
            for k in range(0, len(TIMES), step)
        ]
        (tmp_path / "nav.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        nav = read_nav_csv(tmp_path / "nav.csv")
        got = interpolate(nav, _events(EVENT_TIMES), FRAME, TrajectoryImportOptions())
        assert np.abs(got.velocity_ned - truth).max() < tol, step


def test_job_refuses_an_event_outside_and_writes_nothing(tmp_path, records):
    text = f"image_id,time\nIMG_A,{float(EVENT_TIMES[0])!r}\nIMG_B,{float(TIMES[-1]) + 3.0!r}\n"
    with pytest.raises(InputError, match=r"events\.csv, row 3: image 'IMG_B'"):
        _run(tmp_path, records, text)
    assert not (tmp_path / "traj.csv").exists() and not (tmp_path / "eo.csv").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["events.csv", "job.out"]


def test_hermite_positions_equal_scipys_cubic_hermite_spline():
    from lidarphoto.core.photo.navigation import _hermite
    from scipy.interpolate import CubicHermiteSpline

    rng = np.random.default_rng(5)
    tk = np.cumsum(rng.uniform(0.002, 0.01, 40))
    xyz, vel = rng.normal(0, 100, (40, 3)), rng.normal(0, 60, (40, 3))
    t = rng.uniform(tk[0], tk[-1], 500)
    j = np.clip(np.searchsorted(tk, t, side="right") - 1, 0, len(tk) - 2)
    got = _hermite(tk, xyz, vel, j, t)
    np.testing.assert_allclose(got, CubicHermiteSpline(tk, xyz, vel, axis=0)(t), atol=1e-9)


def test_command_line_utc_events_and_a_truncated_sbet(tmp_path, records, capsys):
    from lidarphoto.core.cli import main as cli_main

    sbet = _sbet(tmp_path / "cli.out", records)
    # the same instants as UTC date-times: GPS second of week 345600.55 on Thursday
    # 2026-12-03 (week 2447 began on Sunday 2026-11-29) is 00:00:00.55 GPS = 23:59:42.55 UTC
    events = tmp_path / "utc.csv"
    events.write_text("image_id,time\nA,2026-12-02T23:59:42.55Z\n", encoding="utf-8")
    rc = cli_main(["importtrajectory", "--input", str(sbet), "--events", str(events),
                   "--event-time", "utc", "--crs", CRS])  # fmt: skip
    out = capsys.readouterr().out.splitlines()
    assert rc == 0 and out[0].startswith("image_id,time") and out[1].startswith("A,345600.55")
    sbet.write_bytes(sbet.read_bytes()[:-1])
    rc = cli_main(["importtrajectory", "--input", str(sbet), "--events", str(events),
                   "--event-time", "utc", "--crs", CRS,
                   "--output-trajectory", str(tmp_path / "t.csv")])  # fmt: skip
    assert rc == 2 and "cli.out: " in capsys.readouterr().err
    assert not (tmp_path / "t.csv").exists()
