"""Benchmark of ``importtrajectory`` on a 1-hour 200 Hz SBET (720,000 records, 98 MB).

    python bench/bench_trajectory_import.py make DIR      # the SBET, 3,600 events (1 Hz), truth
    lidarphoto importtrajectory --input DIR/sbet_1h.out --events DIR/events.csv \
        --crs EPSG:31983 --output-trajectory DIR/traj.csv      # timed as a whole process
    python bench/bench_trajectory_import.py check DIR     # errors against the analytic truth
    python bench/bench_trajectory_import.py naive DIR     # the yardstick (below)

The flight is core/simulation/navigation.py's (60 m/s, turning, a roll manoeuvre every 15 s,
heading through north every 3 minutes, a wander angle swinging through zero), sampled at
200 Hz for 3,600 s; the events fall between records (0.4 ms past a record plus a ramp), and
20 more in the intervals where the file's heading wraps. No peer tool was available on this
machine, so the yardstick ``naive`` is what a user writes by hand: numpy reads the file and
every field is interpolated linearly (np.interp), angles included, the heading taken as
platform heading - wander but not unwrapped: as fast as a reader can be, and it shows the
error the rigorous method avoids.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

CRS = "EPSG:31983"
RATE_HZ, HOURS = 200.0, 1.0


def make(folder: Path) -> None:
    from lidarphoto.core.geometry.frames import MappingFrame
    from lidarphoto.core.io.sbet import sbet_records, write_sbet
    from lidarphoto.core.simulation.navigation import SimulatedFlight

    frame = MappingFrame.from_user_input(CRS)
    sim = SimulatedFlight(frame)
    n = int(HOURS * 3600 * RATE_HZ)
    t = sim.t0 + np.arange(n) / RATE_HZ
    rec = sim.records(t)
    llh_rad = np.column_stack([np.radians(rec["llh"][:, :2]), rec["llh"][:, 2]])
    folder.mkdir(parents=True, exist_ok=True)
    write_sbet(folder / "sbet_1h.out", sbet_records(t, llh_rad, rec["v_ned"], rec["rph"],
                                                     rec["wander"]))  # fmt: skip
    k = np.arange(1, int(HOURS * 3600) - 1)
    te = sim.t0 + k + 0.0004 + 0.0046 * (k % 100) / 100.0  # never on a record
    # plus one event in the middle of every interval where the file's heading (platform
    # heading - wander, each in [0, 2 pi)) jumps by a turn: the trap of angle interpolation
    true_heading = np.mod(rec["rph"][:, 2] + rec["wander"], 2 * np.pi) - rec["wander"]
    wraps = np.flatnonzero(np.abs(np.diff(true_heading)) > np.pi)
    te = np.concatenate([te, t[wraps] + 0.5 / RATE_HZ])
    names = [f"IMG_{i:05d}" for i in k] + [f"WRAP_{i:03d}" for i in range(len(wraps))]
    order = np.argsort(te)
    te, names = te[order], [names[i] for i in order]
    lines = ["image_id,time"] + [f"{i},{float(x)!r}" for i, x in zip(names, te)]
    (folder / "events.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    xyz, _ = sim.position(te)
    wrap = np.array([name.startswith("WRAP") for name in names])
    np.savez(folder / "truth.npz", time=te, enh=frame.ecef_to_map(xyz), rph=sim.attitude(te),
             wrap=wrap)  # fmt: skip
    print(f"{n} records, {len(te)} events ({wrap.sum()} in a heading wrap) -> {folder}")


def _errors(enh: np.ndarray, rph_deg: np.ndarray, truth) -> str:
    from lidarphoto.core.geometry.rotations import rph_to_matrix
    from scipy.spatial.transform import Rotation

    pos = np.linalg.norm(enh - truth["enh"], axis=1)
    r_true = Rotation.from_matrix(rph_to_matrix(*truth["rph"].T))
    r_got = Rotation.from_matrix(rph_to_matrix(*np.radians(rph_deg).T))
    att = np.degrees((r_true.inv() * r_got).magnitude())
    wrap = truth["wrap"]
    return (f"position max {pos.max():.3g} m; attitude median {np.median(att):.3g} deg, max "
            f"{att[~wrap].max():.3g} deg ({(~wrap).sum()} events between records), max "
            f"{att[wrap].max():.3g} deg ({wrap.sum()} events in heading wraps)")  # fmt: skip


def check(folder: Path) -> None:
    from lidarphoto.core.io.trajectory import read_trajectory_csv

    truth = np.load(folder / "truth.npz")
    traj = read_trajectory_csv(folder / "traj.csv")
    print(
        f"importtrajectory: {len(traj)} events; "
        + _errors(traj.position, np.degrees(traj.rph), truth)
    )


def naive(folder: Path) -> None:
    """Linear interpolation of every field, angles as numbers (the yardstick)."""
    data = np.fromfile(folder / "sbet_1h.out", dtype="<f8").reshape(-1, 17)
    events = np.genfromtxt(folder / "events.csv", delimiter=",", skip_header=1, usecols=1)
    cols = [np.interp(events, data[:, 0], data[:, c]) for c in (1, 2, 3, 7, 8)]
    heading = np.interp(events, data[:, 0], data[:, 9] - data[:, 10])
    if len(sys.argv) > 3:  # also report its errors (not part of the timed run)
        from pyproj import Transformer

        truth = np.load(folder / "truth.npz")
        to_map = Transformer.from_crs("EPSG:4674", CRS, always_xy=True)
        e, n = to_map.transform(np.degrees(cols[1]), np.degrees(cols[0]))
        enh = np.column_stack([e, n, cols[2]])
        rph = np.degrees(np.column_stack([cols[3], cols[4], heading]))
        print("naive: " + _errors(enh, rph, truth))


if __name__ == "__main__":
    {"make": make, "check": check, "naive": naive}[sys.argv[1]](Path(sys.argv[2]))
