"""Flight simulator: paper preset geometry, files round trip, observation table errors."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.io.camera import read_camera_json
from lidarphoto.core.io.control import read_lcps_csv, read_lines_csv
from lidarphoto.core.io.observations import read_observations_csv
from lidarphoto.core.io.planes import read_planes_csv
from lidarphoto.core.io.trajectory import read_trajectory_csv
from lidarphoto.core.photo.boresight import calibrate
from lidarphoto.core.photo.boresight_setup import BoresightOptions
from lidarphoto.core.photo.mount import Mount
from lidarphoto.core.simulation.flight import FlightConfig, paper_config, simulate_flight


def test_paper_preset_has_the_papers_geometry():
    sim = simulate_flight(paper_config(), seed=0)
    t = sim.trajectory
    assert len(t) == 6 and sorted(set(t.group)) == ["NE", "SW"]
    assert [t.group.count(g) for g in ("NE", "SW")] == [3, 3]
    assert len(sim.planes) == 76 and len(sim.check_lcps) == 15
    xy = sim.truth.trajectory.position[:3, :2]
    base = np.linalg.norm(np.diff(xy, axis=0), axis=1)
    np.testing.assert_allclose(base, 0.4 * 11310 * 0.006 * 1600 / 100.4, rtol=1e-9)  # ~433 m
    assert sim.camera.height_px == 11310 and sim.camera.width_px == 17310
    # INS noise of the POS AV 310 grade: attitude errors of the order of 0.015 deg
    d = np.degrees(t.rph - sim.truth.trajectory.rph)
    assert np.all(np.abs(d[:, :2]) < 0.015 * 5) and np.any(d != 0)


def test_files_round_trip_and_give_the_same_calibration(tmp_path):
    cfg = FlightConfig(
        n_buildings=9,
        n_planes=20,
        town_size_m=600.0,
        n_check=2,
        types=("tie", "line", "lcp", "check"),
    )
    sim = simulate_flight(cfg, seed=3)
    paths = sim.write(tmp_path)
    traj = read_trajectory_csv(paths["trajectory"])
    cam = read_camera_json(paths["camera"])
    planes = read_planes_csv(paths["planes"])
    lines = read_lines_csv(paths["lines"])
    lcps = read_lcps_csv(paths["lcps"])
    obs = read_observations_csv(paths["observations"])
    assert obs.type == sim.observations.type and len(planes) == 20
    np.testing.assert_allclose(obs.pixels, sim.observations.pixels, rtol=0, atol=1e-9)
    opts = BoresightOptions(snooping=False)
    a = calibrate(
        sim.trajectory,
        sim.camera,
        sim.mount,
        sim.crs,
        sim.observations,
        sim.planes,
        sim.lines,
        sim.lcps,
        options=opts,
    )
    b = calibrate(
        traj,
        cam,
        Mount(sim.mount.lever_arm, sim.mount.nominal, sim.mount.boresight),
        sim.crs,
        obs,
        planes,
        lines,
        lcps,
        options=opts,
    )
    np.testing.assert_allclose(a.boresight, b.boresight, atol=1e-9)


def test_observation_table_errors_name_row_and_column(tmp_path):
    p = tmp_path / "obs.csv"
    p.write_text(
        "image_id,point_id,col,row,sigma_px,type,target_id\n"
        "a,1,10,20,0.5,tie,3\n"
        "a,2,10,abc,0.5,tie,3\n"
    )
    with pytest.raises(InputError) as info:
        read_observations_csv(p)
    assert info.value.row == 3 and info.value.column == "row"
    p.write_text("image_id,point_id,col,row,sigma_px,type,target_id\na,1,10,20,0.5,plane,3\n")
    with pytest.raises(InputError) as info:
        read_observations_csv(p)
    assert info.value.row == 2 and info.value.column == "type"
    p.write_text("image_id,point_id,col,row,sigma_px,type,target_id\na,1,10,20,-1,tie,3\n")
    with pytest.raises(InputError, match="sigma_px"):
        read_observations_csv(p)


def test_noise_free_simulation_projects_consistently():
    """With exact data the tie points fit their planes and images to rounding level."""
    sim = simulate_flight(replace(paper_config(), n_check=0, types=("tie",)), seed=1, exact=True)
    res = calibrate(
        sim.trajectory,
        sim.camera,
        sim.mount,
        sim.crs,
        sim.observations,
        sim.planes,
        options=BoresightOptions(snooping=False),
    )
    v = res.residuals.v_px[res.residuals.used]
    assert np.nanmax(np.abs(v)) < 1e-4
