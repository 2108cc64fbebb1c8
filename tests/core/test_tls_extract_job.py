"""extracttlstargets on simulated scans written as PLY (ASCII, binary) and LAS, then
tlscalibration on its table: the stations come out where they were simulated."""

from __future__ import annotations

import csv
from dataclasses import replace

import laspy
import numpy as np
import pytest
from lidarphoto.core.errors import AdjustmentError, InputError
from lidarphoto.core.io.scans import read_scan
from lidarphoto.core.jobs import extract_tls_targets, tls_calibration
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.simulation.tls import room_network, scene_from_network, simulate_scan

STATIONS = (0, 1, 2)


def _write_ply(path, xyz, intensity, binary):
    head = ("ply\nformat " + ("binary_little_endian" if binary else "ascii") + " 1.0\n"
            f"comment simulated\nelement vertex {len(xyz)}\nproperty double x\n"
            "property double y\nproperty double z\nproperty float intensity\n"
            "end_header\n")  # fmt: skip
    with open(path, "wb") as fh:
        fh.write(head.encode("ascii"))
        if binary:
            rec = np.empty(len(xyz), dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8"),
                                            ("i", "<f4")])  # fmt: skip
            rec["x"], rec["y"], rec["z"], rec["i"] = xyz[:, 0], xyz[:, 1], xyz[:, 2], intensity
            fh.write(rec.tobytes())
        else:
            np.savetxt(fh, np.column_stack([xyz, intensity]), fmt="%.6f")


def _write_las(path, xyz, intensity):
    header = laspy.LasHeader(point_format=1, version="1.2")
    header.scales = np.array([0.0001] * 3)
    header.offsets = np.zeros(3)
    las = laspy.LasData(header)
    las.x, las.y, las.z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    las.intensity = np.round(intensity * 65535).astype(np.uint16)
    las.write(str(path))


@pytest.fixture(scope="module")
def scans(tmp_path_factory):
    d = tmp_path_factory.mktemp("scans")
    truth = room_network()  # the paper's APs are in the recorded points
    scene, t2 = scene_from_network(truth, kind="sphere")
    keep = np.arange(0, 102, 7)
    scene = replace(scene, sphere_ids=tuple(scene.sphere_ids[i] for i in keep),
                    sphere_xyz=scene.sphere_xyz[keep])  # fmt: skip
    paths = []
    for k in STATIONS:
        s = simulate_scan(scene, t2, k, outlier_fraction=0.2, rng=k)
        name = d / t2.station_ids[k]
        if k == 0:
            p = name.with_suffix(".ply")
            _write_ply(p, s.xyz, s.intensity, binary=True)
        elif k == 1:
            p = name.with_suffix(".ply")
            _write_ply(p, s.xyz, s.intensity, binary=False)
        else:
            p = name.with_suffix(".las")
            _write_las(p, s.xyz, s.intensity)
        paths.append(str(p))
    return d, paths, t2, scene


def test_scan_readers_agree(scans):
    _, paths, _, _ = scans
    a, ia = read_scan(paths[0])
    assert a.shape[1] == 3 and np.nanmax(ia) == 1.0
    c, _ = read_scan(paths[2])
    assert len(c) > 1000


def test_extraction_then_registration(scans, tmp_path):
    _, paths, t2, scene = scans
    out = tmp_path / "targets.csv"
    res = run_job(extract_tls_targets, {"SCANS": paths, "OUTPUT": str(out)})
    with open(out, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert res.results["TARGETS"] == len(rows) >= 3 * 10
    # the same sphere has the same id in every scan: map ids to the true spheres
    from lidarphoto.core.geometry.rotations import opk_to_matrix

    truth_of = {}
    for r in rows:
        k = t2.station_ids.index(r["station_id"])
        pose = t2.poses[k]
        world = opk_to_matrix(*pose[3:]).T @ np.array([float(r[c]) for c in "xyz"]) + pose[:3]
        j = int(np.argmin(np.linalg.norm(scene.sphere_xyz - world, axis=1)))
        assert np.linalg.norm(scene.sphere_xyz[j] - world) < 0.01  # APs shift it by mm
        truth_of.setdefault(r["target_id"], set()).add(j)
    assert all(len(v) == 1 for v in truth_of.values())
    # the table registers the stations: distances between them as simulated, with the APs
    # the scans were simulated with; without them data snooping rejects what the model
    # cannot explain until the rest passes the global test: the run fails its checks
    outs = {"OUTPUT_STATIONS": str(tmp_path / "s.csv"), "OUTPUT_APS": str(tmp_path / "a.csv"),
            "OUTPUT_HTML": str(tmp_path / "r.html")}  # fmt: skip
    with pytest.raises(AdjustmentError, match=r"data snooping rejected (\d+) of (\d+) "
                       r"observations .* explain at most [0-3] "):  # fmt: skip
        run_job(tls_calibration, {"OBSERVATIONS": str(out), "AP_SET": "none", **outs})
    assert not (tmp_path / "s.csv").exists()
    run_job(tls_calibration, {"OBSERVATIONS": str(out), "AP_SET": "paper", **outs})
    with open(tmp_path / "s.csv", newline="", encoding="utf-8") as fh:
        st = {r["station_id"]: np.array([float(r[c]) for c in "XYZ"]) for r in csv.DictReader(fh)}
    for a in range(3):
        for b in range(a + 1, 3):
            sa, sb = t2.station_ids[a], t2.station_ids[b]
            got = np.linalg.norm(st[sa] - st[sb])
            want = np.linalg.norm(t2.poses[a, :3] - t2.poses[b, :3])
            assert abs(got - want) < 0.005, (sa, sb, got, want)


def test_scans_with_the_same_name_are_refused(scans, tmp_path):
    _, paths, _, _ = scans
    with pytest.raises(InputError, match="two scans are named 'S1'"):
        run_job(extract_tls_targets, {"SCANS": [paths[0], paths[0]],
                                      "OUTPUT": str(tmp_path / "t.csv")})  # fmt: skip


def test_unknown_scan_format_is_refused(tmp_path):
    p = tmp_path / "scan.xyz"
    p.write_text("1 2 3\n")
    with pytest.raises(InputError, match="unknown scan format"):
        read_scan(p)
