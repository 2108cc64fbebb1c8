"""lidarphoto:tlscalibration in real QGIS: processing.run and qgis_process on the simulated
cube of Carvalho, Correa & dos Santos (high-end scanner noise)."""

from __future__ import annotations

import csv
import json
import math
import subprocess

import processing
import pytest
from lidarphoto.core.io.tls import write_tls_control_csv, write_tls_observations_csv
from lidarphoto.core.simulation.tls import PAPER_APS, SCANNER_CLASSES, observe, paper_cube
from qgis.core import QgsProcessingException
from qgis_helpers import QGIS_PROCESS

ALG = "lidarphoto:tlscalibration"
ARCSEC = math.pi / (180.0 * 3600.0)


@pytest.fixture(scope="module")
def cube(tmp_path_factory):
    folder = tmp_path_factory.mktemp("tls")
    t = paper_cube()
    obs, _ = observe(t, *SCANNER_CLASSES["high_end"], rng=21)
    write_tls_observations_csv(folder / "obs.csv", obs)
    write_tls_control_csv(folder / "control.csv", t.control())
    return folder


def _aps(path):
    with open(path, newline="", encoding="utf-8") as fh:
        return {r["name"]: r for r in csv.DictReader(fh)}


def _check(aps):
    assert list(aps) == ["a0", "b1", "b2", "c0"]
    for name, row in aps.items():
        truth = PAPER_APS[name] * (1000.0 if name == "a0" else 1.0 / ARCSEC)
        assert abs(float(row["value"]) - truth) < 4 * float(row["std"]), (name, row)


def test_processing_run(provider, cube, tmp_path):
    out = {k: str(tmp_path / f"{k.lower()}.csv") for k in
           ("OUTPUT_STATIONS", "OUTPUT_APS", "OUTPUT_TARGETS", "OUTPUT_RESIDUALS")}  # fmt: skip
    res = processing.run(ALG, {
        "OBSERVATIONS": str(cube / "obs.csv"), "CONTROL": str(cube / "control.csv"),
        "LEVELLED": False, "AP_SET": 1, **out, "OUTPUT_HTML": str(tmp_path / "r.html"),
    })  # fmt: skip
    _check(_aps(out["OUTPUT_APS"]))
    assert res["APS"] == "a0,b1,b2,c0" and 0.8 < res["SIGMA0"] < 1.2
    assert "Correlations" in (tmp_path / "r.html").read_text(encoding="utf-8")


def test_bad_table_is_a_processing_error(provider, tmp_path):
    bad = tmp_path / "o.csv"
    bad.write_text("station_id,target_id,range,hz_deg,vt_deg\nA,T1,5,10,1\nA,T2,5,385,1\n",
                   encoding="utf-8")  # fmt: skip
    with pytest.raises(QgsProcessingException, match=r"row 3.*385 is beyond 360"):
        processing.run(ALG, {"OBSERVATIONS": str(bad), "OUTPUT_STATIONS": str(tmp_path / "s.csv"),
                             "OUTPUT_APS": str(tmp_path / "a.csv"),
                             "OUTPUT_HTML": str(tmp_path / "r.html")})  # fmt: skip


def test_qgis_process(qp_env, cube, tmp_path):
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", ALG, "--", f"OBSERVATIONS={cube / 'obs.csv'}",
         f"CONTROL={cube / 'control.csv'}", "LEVELLED=false",
         f"OUTPUT_STATIONS={tmp_path / 's.csv'}", f"OUTPUT_APS={tmp_path / 'a.csv'}",
         f"OUTPUT_HTML={tmp_path / 'r.html'}"],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert json.loads(r.stdout)["results"]["APS"] == "a0,b1,b2,c0"
    _check(_aps(tmp_path / "a.csv"))


@pytest.fixture(scope="module")
def ply_scans(tmp_path_factory):
    """Three simulated PLY scans (ASCII) of 8 spheres, 20 % outliers."""
    from dataclasses import replace

    import numpy as np
    from lidarphoto.core.simulation.tls import room_network, scene_from_network, simulate_scan

    folder = tmp_path_factory.mktemp("scans")
    truth = room_network(aps={})
    scene, t2 = scene_from_network(truth, kind="sphere")
    keep = np.arange(0, 102, 13)
    scene = replace(scene, sphere_ids=tuple(scene.sphere_ids[i] for i in keep),
                    sphere_xyz=scene.sphere_xyz[keep])  # fmt: skip
    paths = []
    for k in range(3):
        s = simulate_scan(scene, t2, k, outlier_fraction=0.2, rng=k)
        p = folder / f"{t2.station_ids[k]}.ply"
        head = (f"ply\nformat ascii 1.0\nelement vertex {len(s.xyz)}\nproperty double x\n"
                "property double y\nproperty double z\nend_header\n")  # fmt: skip
        with open(p, "w", encoding="ascii") as fh:
            fh.write(head)
            np.savetxt(fh, s.xyz, fmt="%.6f")
        paths.append(str(p))
    return paths


def _check_targets(out, count):
    with open(out, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert count == len(rows) >= 18
    assert {r["station_id"] for r in rows} == {"S1", "S2", "S3"}
    ids = [{r["target_id"] for r in rows if r["station_id"] == s} for s in ("S1", "S2", "S3")]
    assert len(ids[0] & ids[1] & ids[2]) >= 4  # common ids: the scans can be registered


def test_extract_targets_processing_run(provider, ply_scans, tmp_path):
    out = tmp_path / "targets.csv"
    res = processing.run("lidarphoto:extracttlstargets",
                         {"SCANS": ply_scans, "KIND": 0, "OUTPUT": str(out)})  # fmt: skip
    _check_targets(out, res["TARGETS"])


def test_extract_targets_qgis_process(qp_env, ply_scans, tmp_path):
    out = tmp_path / "targets.csv"
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", "lidarphoto:extracttlstargets", "--",
         *(f"SCANS={p}" for p in ply_scans), f"OUTPUT={out}"],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    _check_targets(out, json.loads(r.stdout)["results"]["TARGETS"])


@pytest.fixture(scope="module")
def las_field(tmp_path_factory):
    """Room network (no APs): target-centre observations, control and three LAS/LAZ scans."""
    from dataclasses import replace

    import laspy
    import numpy as np
    from lidarphoto.core.simulation.tls import room_network, scene_from_network, simulate_scan

    folder = tmp_path_factory.mktemp("reg")
    scene, t2 = scene_from_network(room_network(aps={}), kind="sphere")
    keep = np.arange(0, len(t2.target_ids), 5)
    scene = replace(scene, sphere_ids=tuple(scene.sphere_ids[i] for i in keep),
                    sphere_xyz=scene.sphere_xyz[keep])  # fmt: skip
    t2 = replace(t2, target_ids=scene.sphere_ids, target_xyz=scene.sphere_xyz)
    obs, _ = observe(t2, *SCANNER_CLASSES["high_end"], rng=8)
    write_tls_observations_csv(folder / "obs.csv", obs)
    write_tls_control_csv(folder / "control.csv", t2.control())
    paths, sims = [], []
    for k in range(3):
        s = simulate_scan(scene, t2, k, spacing_m=0.006, rng=40 + k)
        header = laspy.LasHeader(point_format=0, version="1.2")
        header.scales, header.offsets = np.full(3, 0.0001), np.zeros(3)
        las = laspy.LasData(header)
        las.x, las.y, las.z = s.xyz[:, 0], s.xyz[:, 1], s.xyz[:, 2]
        p = folder / f"{t2.station_ids[k]}{'.laz' if k == 0 else '.las'}"
        las.write(str(p))
        paths.append(str(p))
        sims.append(s)
    return folder, paths, t2, scene, sims


def test_registered_scans_processing_run(provider, las_field, tmp_path):
    import laspy
    import numpy as np

    folder, paths, t2, scene, sims = las_field
    res = processing.run(ALG, {
        "OBSERVATIONS": str(folder / "obs.csv"), "CONTROL": str(folder / "control.csv"),
        "LEVELLED": False, "AP_SET": 0, "SCANS": paths, "OUTPUT_FOLDER": str(tmp_path / "reg"),
        "OUTPUT_STATIONS": str(tmp_path / "s.csv"), "OUTPUT_APS": str(tmp_path / "a.csv"),
        "OUTPUT_HTML": str(tmp_path / "r.html"),
    })  # fmt: skip
    assert res["REGISTERED"] == 3 and res["OUTPUT_FOLDER"] == str(tmp_path / "reg")
    for k, s in enumerate(sims):
        name = f"{t2.station_ids[k]}_registered{'.laz' if k == 0 else '.las'}"
        las = laspy.read(str(tmp_path / "reg" / name))
        xyz = np.column_stack([las.x, las.y, las.z])
        on = s.label >= 0
        dist = np.linalg.norm(xyz[on] - scene.sphere_xyz[s.label[on]], axis=1) - scene.radius
        # 1 mm point noise, stations from 1.2 mm / 8" target centres: on the true spheres
        assert abs(float(np.mean(dist))) < 0.5e-3
        assert float(np.sqrt(np.mean(dist**2))) < 1.5e-3


def test_registered_scans_need_a_folder(provider, las_field, tmp_path):
    folder, paths, *_ = las_field
    with pytest.raises(QgsProcessingException, match="no OUTPUT_FOLDER"):
        processing.run(ALG, {
            "OBSERVATIONS": str(folder / "obs.csv"), "SCANS": paths,
            "OUTPUT_STATIONS": str(tmp_path / "s.csv"), "OUTPUT_APS": str(tmp_path / "a.csv"),
            "OUTPUT_HTML": str(tmp_path / "r.html"),
        })  # fmt: skip
    assert not any(tmp_path.iterdir())
