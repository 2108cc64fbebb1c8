"""E57 scans (optional pye57): simulated scans written with pye57's own writer are read by
extracttlstargets, whose sphere centres lie where they were simulated, and registered by
tlscalibration into LAS files whose points lie on the true spheres."""

from __future__ import annotations

import csv
from dataclasses import replace

import laspy
import numpy as np
import pytest
from lidarphoto.core.geometry.rotations import opk_to_matrix
from lidarphoto.core.io.scans import read_scan
from lidarphoto.core.io.tls import write_tls_control_csv
from lidarphoto.core.jobs import extract_tls_targets, tls_calibration
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.simulation.tls import room_network, scene_from_network, simulate_scan

pye57 = pytest.importorskip("pye57")
S_RANGE, S_ANGLE = 0.001, 20e-6  # simulate_scan's default point noise


@pytest.fixture(scope="module")
def e57_scans(tmp_path_factory):
    d = tmp_path_factory.mktemp("e57")
    scene, t2 = scene_from_network(room_network(aps={}), kind="sphere")
    keep = np.arange(0, len(t2.target_ids), 6)
    scene = replace(scene, sphere_ids=tuple(scene.sphere_ids[i] for i in keep),
                    sphere_xyz=scene.sphere_xyz[keep])  # fmt: skip
    t2 = replace(t2, target_ids=scene.sphere_ids, target_xyz=scene.sphere_xyz)
    paths, sims = [], []
    for k in range(3):
        s = simulate_scan(scene, t2, k, spacing_m=0.004, outlier_fraction=0.1, rng=30 + k)
        p = d / f"{t2.station_ids[k]}.e57"
        e57 = pye57.E57(str(p), mode="w")
        e57.write_scan_raw({"cartesianX": s.xyz[:, 0], "cartesianY": s.xyz[:, 1],
                            "cartesianZ": s.xyz[:, 2],
                            "intensity": np.clip(s.intensity, 0.0, 1.0)})  # fmt: skip
        e57.close()
        paths.append(str(p))
        sims.append(s)
    write_tls_control_csv(d / "control.csv", t2.control())
    return d, paths, t2, scene, sims


def test_e57_reads_the_points_written(e57_scans):
    _, paths, _, _, sims = e57_scans
    xyz, intensity = read_scan(paths[0])
    assert np.allclose(xyz, sims[0].xyz, atol=1e-9)
    assert np.isfinite(intensity).all() and np.nanmax(intensity) == 1.0


def test_extract_targets_from_e57(e57_scans, tmp_path):
    d, paths, t2, scene, _ = e57_scans
    out = tmp_path / "targets.csv"
    res = run_job(extract_tls_targets, {"SCANS": paths, "CONTROL": str(d / "control.csv"),
                                        "OUTPUT": str(out)})  # fmt: skip
    with open(out, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert res.results["TARGETS"] == len(rows) >= 3 * 8
    at = {t: i for i, t in enumerate(scene.sphere_ids)}
    for r in rows:
        k = t2.station_ids.index(r["station_id"])
        pose = t2.poses[k]
        # the true centre in this scanner's frame (no APs were simulated)
        want = opk_to_matrix(*pose[3:]) @ (scene.sphere_xyz[at[r["target_id"]]] - pose[:3])
        got = np.array([float(r[c]) for c in "xyz"])
        sigma = np.array([float(r[f"s_{c}"]) for c in "xyz"])
        # the centre sigma from the point noise (~0.1 mm) is 2-3 times optimistic at worst
        assert np.all(np.abs(got - want) < 5 * sigma + 0.3e-3), (r["station_id"],
                                                                 r["target_id"], got - want)


def test_register_e57_scans(e57_scans, tmp_path):
    d, paths, t2, scene, sims = e57_scans
    table = tmp_path / "targets.csv"
    run_job(extract_tls_targets, {"SCANS": paths, "CONTROL": str(d / "control.csv"),
                                  "OUTPUT": str(table)})  # fmt: skip
    res = run_job(tls_calibration, {
        "OBSERVATIONS": str(table), "CONTROL": str(d / "control.csv"), "AP_SET": "none",
        "LEVELLED": False, "SCANS": paths, "OUTPUT_FOLDER": str(tmp_path / "reg"),
        "OUTPUT_STATIONS": str(tmp_path / "s.csv"), "OUTPUT_APS": str(tmp_path / "a.csv"),
        "OUTPUT_HTML": str(tmp_path / "r.html")})  # fmt: skip
    assert res.results["REGISTERED"] == 3
    for k, s in enumerate(sims):
        las = laspy.read(str(tmp_path / "reg" / f"{t2.station_ids[k]}_registered.las"))
        xyz = np.column_stack([las.x, las.y, las.z])
        on = s.label >= 0
        dist = np.linalg.norm(xyz[on] - scene.sphere_xyz[s.label[on]], axis=1) - scene.radius
        # 1 mm range noise and the pose from target centres of ~0.2 mm: on the true spheres
        assert abs(float(np.mean(dist))) < 0.5e-3
        assert float(np.sqrt(np.mean(dist**2))) < 1.5 * S_RANGE
        # the intensity carried over (scaled to 0-65535)
        assert np.corrcoef(np.asarray(las.intensity, float), s.intensity)[0, 1] > 0.999
