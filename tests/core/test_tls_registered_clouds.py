"""tlscalibration's registered clouds (SCANS, OUTPUT_FOLDER) against truth: simulated scans of
sphere targets from the room network's stations (known poses and inserted APs), written as
LAS, LAZ and PLY; after the adjustment every scan point lies on its true sphere in the
control's frame, and the sphere centres from different stations coincide."""

from __future__ import annotations

import csv
import math
from dataclasses import replace

import laspy
import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.io.scans import read_scan, write_registered_scan
from lidarphoto.core.io.tls import write_tls_control_csv, write_tls_observations_csv
from lidarphoto.core.jobs import tls_calibration
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.simulation.tls import (
    SCANNER_CLASSES,
    observe,
    room_network,
    scene_from_network,
    simulate_scan,
)
from lidarphoto.core.tls.registration import remove_ap_corrections, scanner_to_object

ARCSEC = math.pi / (180.0 * 3600.0)
#: Inserted APs, large enough that leaving them in the points is seen (8 mm, 20-40").
APS = {"a0": 0.008, "b1": 40 * ARCSEC, "b2": 30 * ARCSEC, "c0": 20 * ARCSEC}
S_RANGE, S_ANGLE = 0.0005, 10e-6  # scan point noise: 0.5 mm, 10 urad
SUFFIX = {0: ".laz", 1: ".las", 2: ".ply"}


def _write_las(path, xyz, intensity):
    header = laspy.LasHeader(point_format=1, version="1.2")
    header.scales = np.array([0.0001] * 3)
    header.offsets = np.zeros(3)
    las = laspy.LasData(header)
    las.x, las.y, las.z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    las.intensity = np.round(np.clip(intensity, 0, 1) * 65535).astype(np.uint16)
    las.gps_time = np.arange(len(xyz), dtype=np.float64)  # a dimension that must be kept
    las.write(str(path))


@pytest.fixture(scope="module")
def field(tmp_path_factory):
    d = tmp_path_factory.mktemp("reg")
    scene, t2 = scene_from_network(room_network(aps=APS), kind="sphere")
    keep = np.arange(0, len(t2.target_ids), 4)
    scene = replace(scene, sphere_ids=tuple(scene.sphere_ids[i] for i in keep),
                    sphere_xyz=scene.sphere_xyz[keep])  # fmt: skip
    t2 = replace(t2, target_ids=scene.sphere_ids, target_xyz=scene.sphere_xyz)
    obs, _ = observe(t2, *SCANNER_CLASSES["high_end"], rng=5)
    write_tls_observations_csv(d / "obs.csv", obs)
    write_tls_control_csv(d / "control.csv", t2.control())
    paths, sims = [], {}
    for k, sid in enumerate(t2.station_ids):
        s = simulate_scan(scene, t2, k, spacing_m=0.006, sigma_range_m=S_RANGE,
                          sigma_angle_rad=S_ANGLE, rng=10 + k)  # fmt: skip
        p = d / "scans" / (sid + SUFFIX.get(k, ".las"))
        p.parent.mkdir(exist_ok=True)
        if p.suffix == ".ply":
            head = (f"ply\nformat ascii 1.0\nelement vertex {len(s.xyz)}\nproperty double x\n"
                    "property double y\nproperty double z\nend_header\n")  # fmt: skip
            with open(p, "w", encoding="ascii") as fh:
                fh.write(head)
                np.savetxt(fh, s.xyz, fmt="%.7f")
        else:
            _write_las(p, s.xyz, s.intensity)
        paths.append(str(p))
        sims[sid] = s
    return d, paths, t2, scene, sims


def _run(field, tmp_path, **extra):
    d, paths, *_ = field
    outs = {"OUTPUT_STATIONS": str(tmp_path / "s.csv"), "OUTPUT_APS": str(tmp_path / "a.csv"),
            "OUTPUT_HTML": str(tmp_path / "r.html")}  # fmt: skip
    raw = {"OBSERVATIONS": str(d / "obs.csv"), "CONTROL": str(d / "control.csv"),
           "LEVELLED": False, "AP_SET": "paper", "SCANS": paths,
           "OUTPUT_FOLDER": str(tmp_path / "reg"), **outs, **extra}  # fmt: skip
    return run_job(tls_calibration, raw)


def _stations(path):
    with open(path, newline="", encoding="utf-8") as fh:
        return {r["station_id"]: r for r in csv.DictReader(fh)}


def _fit_centre(p, radius, station):
    """Least-squares centre of a sphere of known radius (Gauss-Newton, independent of core)."""
    m = p.mean(axis=0)
    c = m + radius * (m - station) / np.linalg.norm(m - station)
    for _ in range(10):
        u = p - c
        r = np.linalg.norm(u, axis=1)
        j = -u / r[:, None]
        dc = np.linalg.lstsq(j, -(r - radius), rcond=None)[0]
        c = c + dc
    return c


def _surface_distance(xyz, sim, scene):
    on = sim.label >= 0
    c = scene.sphere_xyz[sim.label[on]]
    return np.linalg.norm(xyz[on] - c, axis=1) - scene.radius


def test_registered_scans_lie_on_the_true_spheres(field, tmp_path):
    _, paths, t2, scene, sims = field
    res = _run(field, tmp_path)
    assert res.results["REGISTERED"] == len(paths) == 6
    st = _stations(tmp_path / "s.csv")
    centres: dict[int, list[np.ndarray]] = {}
    for k, sid in enumerate(t2.station_ids):
        name = f"{sid}_registered" + (".laz" if k == 0 else ".las")
        las = laspy.read(str(tmp_path / "reg" / name))
        xyz = np.column_stack([las.x, las.y, las.z])
        sim = sims[sid]
        assert len(xyz) == len(sim.xyz)
        if k != 2:  # every dimension kept: gps_time as written, in the same order
            assert np.array_equal(np.asarray(las.gps_time), np.arange(len(xyz)))
        dist = _surface_distance(xyz, sim, scene)
        # the point noise (0.5 mm range, the angles 0.05 mm at 5 m) and the pose's sub-mm
        # sigma: the points lie on the true spheres, in the control's (truth) frame
        s_pos = math.sqrt(sum(float(st[sid][f"s_{c}"]) ** 2 for c in "XYZ"))
        assert abs(float(np.mean(dist))) < 3 * s_pos + 0.1e-3, (sid, np.mean(dist))
        assert float(np.sqrt(np.mean(dist**2))) < 1.5 * S_RANGE + 3 * s_pos, sid
        # the station itself where it was simulated, within its reported sigma
        got = np.array([float(st[sid][c]) for c in "XYZ"])
        assert np.all(np.abs(got - t2.poses[k, :3]) < 4 * np.array(
            [float(st[sid][f"s_{c}"]) for c in "XYZ"]) + 1e-6), sid  # fmt: skip
        for j in np.unique(sim.label[sim.label >= 0]):
            pts = xyz[sim.label == j]
            if len(pts) > 200:
                centres.setdefault(int(j), []).append(
                    (_fit_centre(pts, scene.radius, t2.poses[k, :3]), s_pos))
    # the same sphere seen from several stations: its centres coincide with each other and
    # with the truth within the stations' position sigmas and the fit's noise
    seen = [v for v in centres.values() if len(v) >= 2]
    assert len(seen) >= 10
    for j, v in centres.items():
        for c, s_pos in v:
            tol = 4 * s_pos + 4 * S_RANGE / math.sqrt(200) + 0.2e-3
            assert np.linalg.norm(c - scene.sphere_xyz[j]) < tol, (j, c, scene.sphere_xyz[j])
        for a in range(len(v)):
            for b in range(a + 1, len(v)):
                tol = 4 * math.hypot(v[a][1], v[b][1]) + 0.3e-3
                assert np.linalg.norm(v[a][0] - v[b][0]) < tol, j


def test_rigid_pose_only_leaves_the_ap_errors(field, tmp_path):
    """APPLY_APS off: the range offset (8 mm) stays in the points: the check above could
    fail, and the correction is what removes it."""
    _, _, t2, scene, sims = field
    _run(field, tmp_path, APPLY_APS=False)
    sid = t2.station_ids[1]
    las = laspy.read(str(tmp_path / "reg" / f"{sid}_registered.las"))
    dist = _surface_distance(np.column_stack([las.x, las.y, las.z]), sims[sid], scene)
    assert float(np.mean(dist)) < -0.5 * APS["a0"]  # the points sit a0 behind the surface


def test_ap_correction_inverts_the_simulated_errors():
    """remove_ap_corrections undoes the simulator's own AP formulas to the numerical floor."""
    from lidarphoto.core.simulation.tls import _corrections
    from lidarphoto.core.tls.polar import polar_to_cartesian

    rng = np.random.default_rng(1)
    geo = np.column_stack([rng.uniform(1, 50, 500), rng.uniform(-math.pi, math.pi, 500),
                           rng.uniform(-1.4, 1.4, 500)])  # fmt: skip
    dr, dt, da = _corrections(APS, geo[:, 0], geo[:, 1], geo[:, 2], 1.2)
    recorded = polar_to_cartesian(geo + np.column_stack([dr, dt, da]))
    names = tuple(APS)
    got = remove_ap_corrections(recorded, names, [APS[n] for n in names])
    assert np.max(np.abs(got - polar_to_cartesian(geo))) < 1e-9


def test_streamed_chunks_give_the_same_file(field, tmp_path):
    _, paths, t2, *_ = field
    pose = t2.poses[1]
    f = lambda xyz: scanner_to_object(xyz, pose)  # noqa: E731
    a, b = tmp_path / "a.las", tmp_path / "b.las"
    n = write_registered_scan(paths[1], a, f, chunk_size=997)
    assert n == write_registered_scan(paths[1], b, f)
    la, lb = laspy.read(str(a)), laspy.read(str(b))
    assert np.array_equal(la.X, lb.X) and np.array_equal(la.gps_time, lb.gps_time)
    assert np.allclose(la.header.maxs, np.max(np.column_stack([la.x, la.y, la.z]), axis=0))
    src, _ = read_scan(paths[1])
    assert np.allclose(np.column_stack([la.x, la.y, la.z]), f(src), atol=1e-4)


def test_bad_scan_writes_nothing(field, tmp_path):
    _, paths, *_ = field
    bad = tmp_path / "in" / "S5.las"
    bad.parent.mkdir()
    bad.write_bytes(b"LASF" + b"\0" * 300)  # a broken header
    scans = [p for p in paths if not p.endswith("S5.las")] + [str(bad)]
    with pytest.raises(InputError, match=r"S5\.las"):
        _run(field, tmp_path, SCANS=scans)
    assert not (tmp_path / "reg").exists() or not any((tmp_path / "reg").iterdir())
    assert not (tmp_path / "s.csv").exists()


def test_scan_of_an_unknown_station_is_refused(field, tmp_path):
    _, paths, *_ = field
    other = tmp_path / "X9.las"
    other.write_bytes(open(paths[1], "rb").read())
    with pytest.raises(InputError, match=r"'X9'.*no observations"):
        _run(field, tmp_path, SCANS=[*paths, str(other)])
    with pytest.raises(InputError, match="needs SCANS"):
        _run(field, tmp_path, SCANS=None)
    assert not (tmp_path / "reg").exists() and not (tmp_path / "s.csv").exists()


def test_reference_station_datum_without_control(field, tmp_path):
    """No control, DATUM reference: the frame is the reference station's (the first of the
    stations table with a position, held at its given pose), as documented; with the true
    pose of S1 given, the registered points lie on the true spheres again."""
    _, _, t2, scene, sims = field
    table = tmp_path / "stations.csv"
    p = [float(x) for x in t2.poses[0]]
    rows = [f"S1,{p[0]!r},{p[1]!r},{p[2]!r},{math.degrees(p[3])!r},{math.degrees(p[4])!r},"
            f"{math.degrees(p[5])!r},0"]
    rows += [f"{s},,,,,,,0" for s in t2.station_ids[1:]]
    table.write_text("station_id,X,Y,Z,omega_deg,phi_deg,kappa_deg,levelled\n"
                     + "\n".join(rows) + "\n", encoding="utf-8")  # fmt: skip
    _run(field, tmp_path, CONTROL=None, DATUM="reference", STATIONS=str(table))
    st = _stations(tmp_path / "s.csv")
    assert all(float(st["S1"][f"s_{c}"]) == 0.0 for c in "XYZ")  # held by the datum
    with open(tmp_path / "a.csv", newline="", encoding="utf-8") as fh:
        s_a0 = next(float(r["std"]) for r in csv.DictReader(fh) if r["name"] == "a0") * 1e-3
    for k, sid in enumerate(t2.station_ids):
        name = f"{sid}_registered" + (".laz" if k == 0 else ".las")
        las = laspy.read(str(tmp_path / "reg" / name))
        dist = _surface_distance(np.column_stack([las.x, las.y, las.z]), sims[sid], scene)
        # the other stations' sigmas relative to S1 (up to about 0.5 mm in this network), and
        # the rangefinder offset's (0.3 mm), which moves every point along its ray, S1's too
        s_pos = math.sqrt(sum(float(st[sid][f"s_{c}"]) ** 2 for c in "XYZ"))
        s_mean = math.hypot(s_pos, s_a0)
        assert abs(float(np.mean(dist))) < 3 * s_mean + 0.1e-3, (sid, np.mean(dist), s_mean)
        assert float(np.sqrt(np.mean(dist**2))) < 1.5 * S_RANGE + 3 * s_mean, sid
