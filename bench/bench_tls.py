"""TLS self-calibration: recovered vs inserted APs on the cube of Carvalho, Correa & dos Santos,
Monte Carlo against the Cramer-Rao bound, the decorrelation by tilted stations (Lichti 2010),
an independent SciPy peer, the paper's shortfall, and what the user waits for (the job).

Run: .venv/bin/python bench/bench_tls.py [draws] [--targets: section 6 only]
(writes nothing but stdout; bench/tls.md holds the tables of one run)
"""

from __future__ import annotations

import math
import platform
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy
from lidarphoto.core import __version__
from lidarphoto.core.geometry.rotations import opk_to_matrix
from lidarphoto.core.io.tls import write_tls_control_csv, write_tls_observations_csv
from lidarphoto.core.jobs import tls_calibration
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.simulation.tls import (
    PAPER_APS,
    SCANNER_CLASSES,
    observe,
    paper_cube,
    room_network,
)
from lidarphoto.core.tls.calibration import CalibrationOptions, calibrate
from scipy.optimize import least_squares

AS = math.pi / (180 * 3600)
NAMES = ("a0", "b1", "b2", "c0")
SCALE = np.array([1000.0, 1 / AS, 1 / AS, 1 / AS])  # mm, arcsec
TRUTH = np.array([PAPER_APS[n] for n in NAMES])
FREE = CalibrationOptions(levelled=False, snooping=False)


def fmt(v, d=2):
    return " / ".join(f"{x:.{d}f}" for x in v)


# ----------------------------------------------------------------------------- SciPy peer


def peer_residuals(p, obs_polar, st_index, target_xyz, sig, fix_pose=None, aps=True):
    """Our own short rewrite of Eqs. 1-5 (no core.tls code): whitened residuals of the polar
    observations for APs (a0, b1, b2, c0) and the stations' (X0, omega, phi, kappa)."""
    k = 4 if aps else 0
    ap = p[:k] if aps else np.zeros(4)
    poses = fix_pose if fix_pose is not None else p[k:].reshape(-1, 6)
    out = []
    for s in range(poses.shape[0]):
        rows = st_index == s
        x0, (om, ph, ka) = poses[s, :3], poses[s, 3:]
        m = opk_to_matrix(om, ph, ka)
        d = (target_xyz[rows] - x0) @ m.T
        h = np.hypot(d[:, 0], d[:, 1])
        alpha = np.arctan2(d[:, 2], h)
        rho = np.hypot(h, d[:, 2]) + ap[0]
        theta = np.arctan2(d[:, 1], d[:, 0]) + ap[1] / np.cos(alpha) + ap[2] * np.tan(alpha)
        alpha = alpha + ap[3]
        o = obs_polar[rows]
        dt = (theta - o[:, 1] + math.pi) % (2 * math.pi) - math.pi
        out.append(np.column_stack([rho - o[:, 0], dt, alpha - o[:, 2]]) / sig)
    return np.concatenate(out).ravel()


def peer_solve(obs, t, sig, start_poses, aps=True, fix_pose=None):
    st = {s: i for i, s in enumerate(t.station_ids)}
    tg = {s: i for i, s in enumerate(t.target_ids)}
    st_index = np.array([st[s] for s in obs.station])
    xyz = t.target_xyz[[tg[s] for s in obs.target]]
    x0 = np.concatenate([np.zeros(4 if aps else 0),
                         [] if fix_pose is not None else start_poses.ravel()])  # fmt: skip
    r = least_squares(peer_residuals, x0, args=(obs.polar, st_index, xyz, np.array(sig),
                      fix_pose, aps), method="lm", x_scale="jac", xtol=1e-15, ftol=1e-15,
                      gtol=1e-15)  # fmt: skip
    return r.x


def main(draws: int = 1000, only_targets: bool = False) -> None:
    print(f"# date {time.strftime('%Y-%m-%d')}, {platform.processor() or platform.machine()}, "
          f"python {platform.python_version()}, numpy {np.__version__}, scipy "
          f"{scipy.__version__}, lidarphoto {__version__}")  # fmt: skip
    if only_targets:
        targets_from_scans()
        return
    t = paper_cube()
    ctrl = t.control()
    info = t.station_info()

    # 1. noise-free cube: ours, the peer, the paper
    obs, _ = observe(t, exact=True)
    t0 = time.perf_counter()
    cal = calibrate(obs, ctrl, info, FREE)
    t_ours = time.perf_counter() - t0
    start = np.array([[5, 2, 0, 0, 0, math.radians(40)], [2, 5, 0, 0, 0, math.radians(20)],
                      [8, 8, 0, 0, 0, math.radians(10)]], dtype=float)  # fmt: skip
    t0 = time.perf_counter()
    px = peer_solve(obs, t, (0.001, 5 * AS, 5 * AS), start)
    t_peer = time.perf_counter() - t0
    print("\n## 1 noise-free cube (control fixed, 6 free EOPs per station)")
    print(f"inserted  {fmt(TRUTH * SCALE, 3)}  (a0 mm, b1 b2 c0 arcsec)")
    print(f"ours      {fmt(cal.ap * SCALE, 9)}  {t_ours * 1000:.0f} ms")
    print(f"scipy LM  {fmt(px[:4] * SCALE, 9)}  {t_peer * 1000:.0f} ms")
    print(f"max |pose error| ours: {np.abs(cal.pose[:, :3] - t.poses[:, :3]).max():.1e} m, "
          f"{np.abs(cal.pose[:, 3:] - t.poses[:, 3:]).max() / AS:.1e} arcsec")
    for datum in ("inner", "reference"):
        c = calibrate(obs, (), t.station_info(with_pose=True),
                      CalibrationOptions(levelled=False, datum=datum))  # fmt: skip
        print(f"no control, datum {datum:9}: {fmt(c.ap * SCALE, 9)}")

    # 2. the paper's shortfall: registration without APs, then APs with the EOPs held there
    reg = calibrate(obs, ctrl, info, CalibrationOptions(ap_set="none", levelled=False))
    print("\n## 2 registration without APs (the paper's 'Registro')")
    for s, p in zip(reg.stations, reg.pose):
        print(f"station {s}: X0 {fmt(p[:3], 4)} m; omega/phi {fmt(p[3:5] / AS, 1)} arcsec, "
              f"kappa {math.degrees(p[5]):.5f} deg")  # fmt: skip
    fixed = peer_solve(obs, t, (0.001, 5 * AS, 5 * AS), None, fix_pose=reg.pose)
    print(f"APs with the EOPs held at the registration: {fmt(fixed[:4] * SCALE, 2)}")
    one = calibrate(obs, ctrl, [type(i)(i.id, None, None, False) for i in info],
                    CalibrationOptions(levelled=False, max_iterations=1))  # fmt: skip
    print(f"one Gauss-Newton step from the registration start: {fmt(one.ap * SCALE, 3)}")

    # 3. Monte Carlo against the Cramer-Rao bound
    print(f"\n## 3 Monte Carlo, {draws} draws, cube with control")
    for cls, sig in SCANNER_CLASSES.items():
        est, crb, post = [], None, []
        t0 = time.perf_counter()
        for i in range(draws):
            o, _ = observe(t, *sig, rng=10_000 + i)
            c = calibrate(o, ctrl, info, FREE)
            est.append(c.ap)
            post.append(c.ap_std)
            crb = c.ap_std_prior
        dt = (time.perf_counter() - t0) / draws
        err = np.array(est) - TRUTH
        rmse = np.sqrt(np.mean(err**2, axis=0))
        print(f"{cls} ({sig[0] * 1000:.1f} mm, {sig[1] / AS:.0f}\"): mean error "
              f"{fmt(err.mean(0) * SCALE, 3)}; RMSE {fmt(rmse * SCALE, 3)}; CRB "
              f"{fmt(crb * SCALE, 3)}; mean reported sigma "
              f"{fmt(np.mean(post, axis=0) * SCALE, 3)}; RMSE/CRB {fmt(rmse / crb, 3)}; "
              f"{dt * 1000:.0f} ms per adjustment")  # fmt: skip

    # 4. the room: levelled only vs with two stations rolled by 90 degrees
    print("\n## 4 room 12 x 8 x 3.5 m, high-end noise, no control (inner constraints)")
    sig = SCANNER_CLASSES["high_end"]
    for tilted in (False, True):
        r = room_network(tilted=tilted)
        o, _ = observe(r, *sig, rng=5)
        c = calibrate(o, (), r.station_info(), CalibrationOptions())
        names, corr = c.calib_names, c.calib_correlation

        def mx(ap, tails, names=names, corr=corr):
            i = names.index(ap)
            js = [j for j, n in enumerate(names) if n.rsplit(".", 1)[-1] in tails]
            return np.max(np.abs(corr[i, js]))

        print(f"tilted={tilted}: {len(o)} obs; CRB {fmt(c.ap_std_prior * SCALE, 2)}; "
              f"max|r| a0-XY {mx('a0', ('X', 'Y')):.3f} a0-Z {mx('a0', ('Z',)):.3f} "
              f"b1-kappa {mx('b1', ('kappa',)):.3f} b2-tilt {mx('b2', ('omega', 'phi')):.3f} "
              f"c0-Z {mx('c0', ('Z',)):.3f} c0-tilt {mx('c0', ('omega', 'phi')):.3f}")  # fmt: skip
    r = room_network()
    est, crb = [], None
    for i in range(max(draws // 5, 20)):
        o, _ = observe(r, *sig, rng=20_000 + i)
        c = calibrate(o, (), r.station_info(), CalibrationOptions(snooping=False))
        est.append(c.ap)
        crb = c.ap_std_prior
    rmse = np.sqrt(np.mean((np.array(est) - TRUTH) ** 2, axis=0))
    print(f"tilted room Monte Carlo ({len(est)} draws): RMSE {fmt(rmse * SCALE, 3)}, CRB "
          f"{fmt(crb * SCALE, 3)}, RMSE/CRB {fmt(rmse / crb, 3)}")  # fmt: skip

    # 5. what the user waits for: the job, CSV in, CSV + HTML out
    print("\n## 5 the job (read + adjust + write 4 CSV + HTML)")
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        cases = {
            "cube (432 obs)": (t, 1),
            "room (6 stations)": (room_network(), 1),
            "room, 12 stations, two faces": (room_network(levelled_stations=10), 2),
        }
        for label, (net, faces) in cases.items():
            o, _ = observe(net, *sig, rng=3, two_faces=faces == 2)
            write_tls_observations_csv(d / "obs.csv", o)
            write_tls_control_csv(d / "ctrl.csv", net.control())
            vals = {"OBSERVATIONS": str(d / "obs.csv"), "LEVELLED": False,
                    "OUTPUT_STATIONS": str(d / "s.csv"), "OUTPUT_APS": str(d / "a.csv"),
                    "OUTPUT_TARGETS": str(d / "t.csv"), "OUTPUT_RESIDUALS": str(d / "r.csv"),
                    "OUTPUT_HTML": str(d / "r.html")}  # fmt: skip
            if net is t:
                vals["CONTROL"] = str(d / "ctrl.csv")
            else:  # the levelled flags of the stations (the rolled ones are not)
                rows = [f"{s},{int(lv)}" for s, lv in zip(net.station_ids, net.levelled)]
                (d / "st.csv").write_text("station_id,levelled\n" + "\n".join(rows) + "\n")
                vals["STATIONS"] = str(d / "st.csv")
            t0 = time.perf_counter()
            res = run_job(tls_calibration, vals)
            dt = time.perf_counter() - t0
            print(f"{label}: {len(o)} observations, {dt:.2f} s, sigma0 "
                  f"{res.results['SIGMA0']:.3f}")  # fmt: skip
    targets_from_scans()


def targets_from_scans() -> None:
    """6. targets from scans: 102 spheres in the room, 20 % outliers, binary PLY per station."""
    print("\n## 6 extracttlstargets (read PLY + detect + fit + label + write), 3 stations")
    from dataclasses import replace as _replace

    from lidarphoto.core.geometry.rotations import opk_to_matrix as _m
    from lidarphoto.core.jobs import extract_tls_targets
    from lidarphoto.core.simulation.tls import scene_from_network, simulate_scan

    room = room_network()
    scene, t2 = scene_from_network(room, kind="sphere")
    flat = _replace(t2, aps={})
    with tempfile.TemporaryDirectory() as tmp:
        paths, npts = [], 0
        for k in range(3):
            sc = simulate_scan(scene, flat, k, outlier_fraction=0.2, hide_below=0.5, rng=k)
            p = Path(tmp) / f"{t2.station_ids[k]}.ply"
            rec = np.empty(len(sc.xyz), dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8"),
                                               ("intensity", "<f4")])  # fmt: skip
            rec["x"], rec["y"], rec["z"] = sc.xyz.T
            rec["intensity"] = sc.intensity
            head = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(rec)}\n"
                    "property double x\nproperty double y\nproperty double z\n"
                    "property float intensity\nend_header\n")  # fmt: skip
            p.write_bytes(head.encode() + rec.tobytes())
            paths.append(str(p))
            npts += len(rec)
        t0 = time.perf_counter()
        res = run_job(extract_tls_targets, {"SCANS": paths, "OUTPUT": str(Path(tmp) / "t.csv")})
        dt = time.perf_counter() - t0
        _, fits, _ = res.data
        z = []
        for k, fs in enumerate(fits):
            pose = flat.poses[k]
            local = (scene.sphere_xyz - pose[:3]) @ _m(*pose[3:]).T
            for f in fs:
                j = int(np.argmin(np.linalg.norm(local - f.centre, axis=1)))
                z.append((f.centre - local[j]) / f.sigma)
        z = np.array(z)
        print(f"{npts} points, {res.results['TARGETS']} centres in {dt:.1f} s "
              f"({npts / dt / 1e6:.2f} M points/s); centre error / sigma RMS per axis "
              f"{fmt(np.sqrt(np.mean(z**2, axis=0)), 2)}, max {np.abs(z).max():.1f}")  # fmt: skip
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak RSS of this whole script: {peak:.0f} MB")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    main(int(args[0]) if args else 1000, only_targets="--targets" in sys.argv)
