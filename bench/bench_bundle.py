"""Bundle adjustment speed: our engine (analytic Jacobians, reduced camera system, Levenberg-
Marquardt) against Ceres Solver (its BAL example: Levenberg-Marquardt, DENSE_SCHUR, one
thread; the peer in ``../shared/peers/ceres-bal``) on the BAL problems, from the same start,
in interleaved runs; SciPy's ``least_squares`` with a sparse finite-difference Jacobian (the
SciPy cookbook's bundle adjustment) as a second yardstick; and a synthetic 1,000-image block
with 200,000 points (time and peak memory of the whole process).

Run: ``.venv/bin/python bench/bench_bundle.py [ceres|bal|large|all]``; writes its section of
bench/bundle.md (bench/bundle_ap_models.py writes the accuracy section). The BAL files are read
from ``../shared/data/bal`` (not in the repository); the Ceres program from ``$CERES_BAL``
(default ``~/.cache/ceres-bal/ceres_bal``, what ``../shared/peers/ceres-bal/build.sh`` builds).
``bench_bundle.py ours FILE`` runs our engine alone on one BAL file and prints one JSON line
(for timing the whole process from outside).
"""

from __future__ import annotations

import os
import platform
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import scipy
from lidarphoto.core.geometry.snavely import snavely_project
from lidarphoto.core.io.bal import BalProblem, read_bal
from lidarphoto.core.lsq import solve as _solve
from lidarphoto.core.lsq.adjustment import adjust
from lidarphoto.core.lsq.model import AdjustmentOptions, Constraint, GaussMarkovBlock

HERE = Path(__file__).resolve().parent
BAL = HERE.parent.parent / "shared" / "data" / "bal"
PROBLEMS = ("problem-49-7776-pre.txt", "problem-39-18060-pre.txt")
# the iteration trace in CPU time (user + sys of the process): on a shared machine the wall
# time measures the other sessions' load as much as the run
_solve.TRACE_CLOCK = time.process_time


# ----------------------------------------------------------------------------- SciPy cookbook


def cookbook(problem: BalProblem) -> dict:
    """The SciPy cookbook's bundle adjustment: residual function, sparsity pattern of the
    Jacobian, ``least_squares(..., jac_sparsity=A, x_scale='jac', ftol=1e-4, method='trf')``
    (written after the cookbook's description; finite-difference Jacobian)."""
    from scipy.optimize import least_squares
    from scipy.sparse import lil_matrix

    nc, npt = problem.cameras.shape[0], problem.points.shape[0]
    ci, pi = problem.camera_index, problem.point_index

    def residuals(params: np.ndarray) -> np.ndarray:
        cams = params[: nc * 9].reshape(nc, 9)
        pts = params[nc * 9 :].reshape(npt, 3)
        u = snavely_project(cams[ci], pts[pi], jacobian=False)
        return (u - problem.observations).ravel()

    m = ci.size * 2
    A = lil_matrix((m, nc * 9 + npt * 3), dtype=int)
    rows = np.arange(ci.size)
    for s in range(9):
        A[2 * rows, ci * 9 + s] = 1
        A[2 * rows + 1, ci * 9 + s] = 1
    for s in range(3):
        A[2 * rows, nc * 9 + pi * 3 + s] = 1
        A[2 * rows + 1, nc * 9 + pi * 3 + s] = 1
    x0 = np.hstack([problem.cameras.ravel(), problem.points.ravel()])
    f0 = residuals(x0)
    t, cpu = time.perf_counter(), time.process_time()
    res = least_squares(residuals, x0, jac_sparsity=A, verbose=0, x_scale="jac", ftol=1e-4,
                        method="trf")  # fmt: skip
    elapsed, cpu = time.perf_counter() - t, time.process_time() - cpu
    return {
        "initial": 0.5 * float(f0 @ f0),
        "cpu_seconds": cpu,
        "final": float(res.cost),
        "seconds": elapsed,
        "nfev": int(res.nfev),
        "rms": float(np.sqrt(np.mean(res.fun**2))),
    }


# ----------------------------------------------------------------------------- our engine


class _SnavelyModel:
    fresh_jacobian = True  # a new Jacobian on every call: whitened (or taken) in place

    def __call__(self, xl: np.ndarray):
        return snavely_project(xl[:, :9], xl[:, 9:12], joint=True)


def engine(problem: BalProblem, tolerance: float = 1e-10, max_iterations: int = 40,
           function_tolerance: float = 1e-6) -> dict:  # fmt: skip
    """Our adjustment of the same cost ``0.5 sum r^2`` (unit sigmas), points eliminated.

    BAL problems have no datum: the seven similarity parameters are held by minimal
    constraints (the first camera's rotation and translation, and the translation component
    of the second camera that a change of scale moves most), which changes no projection and
    hence not the minimum of the cost. A few points of these problems are seen along nearly
    parallel rays and drift away as the cost keeps falling by tiny amounts; the run stops after
    40 iterations (the condition limit is raised to 1e16 so that they are accepted), or when
    an accepted step lowers the cost by less than ``function_tolerance`` (Ceres' rule and
    default).
    """
    nc, npt = problem.cameras.shape[0], problem.points.shape[0]
    ci, pi = problem.camera_index, problem.point_index
    x0 = np.hstack([problem.cameras.ravel(), problem.points.ravel()])
    names = [f"cam{c} {k}" for c in range(nc) for k in ("r1 r2 r3 t1 t2 t3 f k1 k2".split())]
    names += [f"pt{p} {a}" for p in range(npt) for a in "XYZ"]
    idx = np.concatenate([ci[:, None] * 9 + np.arange(9), nc * 9 + pi[:, None] * 3 + np.arange(3)],
                         axis=1)  # fmt: skip
    block = GaussMarkovBlock("bal", problem.observations, 1.0, idx, _SnavelyModel(),
                             row_names=("x", "y"))  # fmt: skip
    # gauge: camera 0 (r, t) and the scale through camera 1's translation
    from lidarphoto.core.geometry.snavely import rodrigues

    r0, r1 = rodrigues(problem.cameras[:2, :3])
    c0 = -r0.T @ problem.cameras[0, 3:6]
    c1 = -r1.T @ problem.cameras[1, 3:6]
    k = int(np.argmax(np.abs(r1 @ (c1 - c0))))
    held = np.array([0, 1, 2, 3, 4, 5, 9 + 3 + k])
    vals = x0[held]

    def gauge(xl: np.ndarray):
        return (xl[0] - vals)[None], np.eye(7)[None]

    opts = AdjustmentOptions(eliminate=nc * 9 + np.arange(3 * npt).reshape(npt, 3),
                             compute_covariance=False, tolerance=tolerance,
                             max_iterations=max_iterations, condition_limit=1e16,
                             function_tolerance=function_tolerance)  # fmt: skip
    t, cpu = time.perf_counter(), time.process_time()
    res = adjust(x0, names, [block], [Constraint("gauge", held[None], gauge)], opts)
    elapsed, cpu = time.perf_counter() - t, time.process_time() - cpu
    v = res.residuals["bal"].v
    r0 = snavely_project(problem.cameras[ci], problem.points[pi], jacobian=False)
    f0 = r0 - problem.observations
    return {
        "initial": 0.5 * float(np.sum(f0**2)),
        "final": 0.5 * res.omega,
        "seconds": elapsed,
        "cpu_seconds": cpu,
        "iterations": res.iterations,
        "converged": res.converged,
        "rms": float(np.sqrt(np.mean(v**2))),
        "termination": res.termination,
        "trace": [(i, 0.5 * c, t) for i, c, t in res.trace],
        "result": res,
    }


def seconds_to_cost(run: dict, target: float) -> float:
    """CPU seconds of a run of :func:`engine` until its cost first fell to ``target``: the
    whole run less what followed the first iteration at or below it (conservative: the set-up
    and the final statistics count in full). NaN when it never got there."""
    trace = run["trace"]
    hit = [t for _, c, t in trace if c <= target]
    if not hit:
        return float("nan")
    return run["cpu_seconds"] - (trace[-1][2] - hit[0])


def warm_up() -> None:
    """Load the compiled kernels (numba's cache) on the 3-camera BAL file, as a program loads
    its code before it runs: the timed runs then measure the adjustment alone."""
    path = BAL / "dubrovnik-3-7-pre.txt"
    if path.is_file():
        try:
            engine(read_bal(path), max_iterations=2)
        except Exception:  # a gauge-deficient toy: only the kernels matter
            pass


def ours_json(path: Path) -> str:
    """One run of our engine on a BAL file as a JSON line (after :func:`warm_up`)."""
    import json

    warm_up()
    r = engine(read_bal(path), max_iterations=100)
    return json.dumps({k: v for k, v in r.items() if k != "result"})


def ceres_program() -> Path:
    return Path(os.environ.get("CERES_BAL", "~/.cache/ceres-bal/ceres_bal")).expanduser()


def _child(cmd: list[str], env: dict | None = None) -> tuple[dict, float, float]:
    """A program's last JSON line, its wall time and its CPU time (user + sys)."""
    import json
    import resource

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True, check=True, env=env)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    return json.loads(out.stdout.strip().splitlines()[-1]), wall, cpu


def ceres(path: Path, max_iterations: int = 100) -> dict:
    """Ceres' BAL run (DENSE_SCHUR, one thread) as its JSON, with the whole process's
    wall and CPU time."""
    d, d["process_s"], d["process_cpu_s"] = _child(
        [str(ceres_program()), str(path), "DENSE_SCHUR", "1", str(max_iterations)]
    )
    return d


def ours_process(path: Path) -> dict:
    """:func:`ours_json` in a fresh process, with the whole process's wall and CPU time."""
    d, d["process_s"], d["process_cpu_s"] = _child(
        [sys.executable, __file__, "ours", str(path)], dict(os.environ)
    )
    return d


def against_ceres(path: Path, repeats: int = 3) -> dict:
    """Interleaved runs (ours, Ceres, ours, Ceres, ...): per pair the CPU-time ratios of the
    time to Ceres' final cost, of the whole solve and of the whole process; medians over the
    pairs, with the load average before each pair."""
    pairs = []
    for _ in range(repeats):
        load = os.getloadavg()[0]
        o = ours_process(path)
        c = ceres(path)
        to = seconds_to_cost(o, c["final_cost"])
        pairs.append({"ours": o, "ceres": c, "to_cost": to / c["solve_cpu_s"],
                      "whole": o["cpu_seconds"] / c["solve_cpu_s"],
                      "process": o["process_cpu_s"] / c["process_cpu_s"],
                      "wall": o["seconds"] / c["solve_wall_s"], "load": load})  # fmt: skip
    keys = ("to_cost", "whole", "process", "wall", "load")
    med = {k: float(np.median([p[k] for p in pairs])) for k in keys}
    return {"pairs": pairs, **med}


# ----------------------------------------------------------------------------- large block


LARGE_CODE = r"""
import resource, sys, time, json
t0 = time.perf_counter()
from lidarphoto.core.simulation.uav_block import simulate_uav_block
from lidarphoto.core.photo.bundle import bundle_adjust
from lidarphoto.core.photo.bundle_setup import BundleOptions
strips, n_tie = (int(a) for a in sys.argv[2:4]) if len(sys.argv) > 3 else (25, 200000)
blk = simulate_uav_block("none", seed=3, strips=(40,) * strips, n_tie=n_tie, n_control=60,
                         n_check=20, forward_overlap=0.6, side_overlap=0.3)
t1 = time.perf_counter()
c1 = time.process_time()
cov = sys.argv[1] == "1"
res = bundle_adjust([blk.camera], blk.observations, blk.ground, blk.mapping, eo=blk.eo_dg,
                    eo_sigma=blk.eo_sigma,
                    options=BundleOptions(ap_model="none", estimate_interior=False,
                                          robust="none", snooping=False, covariance=cov))
t2 = time.perf_counter()
c2 = time.process_time()
st = res.check.statistics()
print(json.dumps({"images": len(blk.eo_true), "points": len(res.point_id),
                  "observations": len(blk.observations), "simulate_s": t1 - t0,
                  "bundle_s": t2 - t1, "bundle_cpu_s": c2 - c1,
                  "iterations": res.adjustment.iterations,
                  "converged": res.adjustment.converged, "sigma0": res.sigma0,
                  "rms_3d": st["rms_3d"],
                  "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def large(covariance: bool, strips: int = 25, n_tie: int = 200000) -> dict:
    """The block of ``strips`` strips of 40 images in a fresh process (its JSON line)."""
    import json

    env = dict(os.environ)
    out = subprocess.run([sys.executable, "-c", LARGE_CODE, "1" if covariance else "0",
                          str(strips), str(n_tie)], capture_output=True, text=True, env=env,
                         check=True)  # fmt: skip
    return json.loads(out.stdout.strip().splitlines()[-1])


# ----------------------------------------------------------------------------- report


def main(what: str = "all", repeats: int = 3) -> None:
    head = [
        f"Measured {time.strftime('%Y-%m-%d')} on {platform.machine()} ({os.cpu_count()} cores, "
        f"shared), Python {platform.python_version()}, numpy {np.__version__}, scipy "
        f"{scipy.__version__}; one BLAS thread. Wall times carry the noise of a shared machine "
        f"(about +/-30 %; load average {os.getloadavg()[0]:.1f} when the run started).",
        "",
    ]
    if what in ("ceres", "all"):
        write_section(HERE / "bundle.md", "ceres", "\n".join(head + ceres_section(repeats)))
    if what in ("bal", "all"):
        lines = [
            *head,
            "### BAL problems: our engine against SciPy's cookbook, same start, same cost",
            "",
            "Cost = 0.5 sum r^2 (pixels). SciPy: `least_squares(method='trf', x_scale='jac', "
            "ftol=1e-4, jac_sparsity=...)` with its finite-difference Jacobian (the cookbook). "
            "Ours: analytic Jacobians, points eliminated (reduced camera system), "
            "Levenberg-Marquardt, 40 iterations (BAL's nearly unobservable points keep drifting "
            "at tiny gains in cost, so neither solver converges in the strict sense); 'ours to "
            "SciPy's cost' is the CPU time until our cost first fell to SciPy's final cost; the "
            "speed-ups are ratios of CPU time.",
            "",
            "| problem | residuals | initial cost | SciPy final cost | SciPy s (evals) | "
            "ours final cost | ours s (iterations) | ours to SciPy's cost s | speed-up (to "
            "SciPy's cost) | speed-up (SciPy's run against our 40 iterations) |",
            "|---|---|---|---|---|---|---|---|---|---|",
        ]
        for name in PROBLEMS:
            path = BAL / name
            if not path.is_file():
                lines.append(f"| {name} | missing | | | | | | | | |")
                continue
            prob = read_bal(path)
            ours = engine(prob, function_tolerance=0.0)
            sc = cookbook(prob)
            to = {"seconds_to_target": seconds_to_cost(ours, sc["final"])}
            lines.append(
                f"| {name} | {2 * prob.camera_index.size} | {ours['initial']:.6e} | "
                f"{sc['final']:.6e} | {sc['seconds']:.1f} ({sc['nfev']}) | {ours['final']:.6e} | "
                f"{ours['seconds']:.2f} ({ours['iterations']}) | {to['seconds_to_target']:.2f} | "
                f"{sc['cpu_seconds'] / to['seconds_to_target']:.0f}x | "
                f"{sc['cpu_seconds'] / ours['cpu_seconds']:.0f}x |"
            )
            print(lines[-1], flush=True)
        lines.append("")
        write_section(HERE / "bundle.md", "speed", "\n".join(lines))
    if what in ("large", "all"):
        lines = [
            *head,
            "### Synthetic 1,000-image block, 200,000 points",
            "",
            "`simulate_uav_block` with 25 strips of 40 images (60 %/30 % overlap), 200,000 "
            "tie points drawn (those in two or more images kept), 60 control and 20 check "
            "points, direct-georeferencing start (5 m, 1 deg), exterior orientation observed; "
            "camera fixed, no robust stage, no snooping. The whole process (simulation + "
            "bundle) is measured for the peak memory, the compiled kernels loaded from "
            "numba's cache (filled by a smaller block first). The covariance: from 2,500 "
            "reduced parameters on, the entries of the inverse reduced matrix that the "
            "sigmas need from its band Cholesky factor (core/lsq/selected_inverse.py), "
            "not a dense inverse.",
            "",
            "| covariance | images | points | observations | bundle s | bundle CPU s | "
            "iterations | sigma0 | check RMS 3D m | peak RSS MB |",
            "|---|---|---|---|---|---|---|---|---|---|",
        ]
        # numba compiles the kernels once per copy of the package (its cache): an 11-strip
        # block with the covariance (every kernel of the 25-strip runs) fills the cache first
        large(True, strips=11, n_tie=40000)
        for cov in (False, True):
            r = large(cov)
            lines.append(
                f"| {'yes' if cov else 'no'} | {r['images']} | {r['points']} | "
                f"{r['observations']} | {r['bundle_s']:.1f} | {r['bundle_cpu_s']:.1f} | "
                f"{r['iterations']} | "
                f"{r['sigma0']:.3f} | {r['rms_3d']:.3f} | {r['peak_rss_mb']:.0f} |"
            )
            print(lines[-1], flush=True)
        lines.append("")
        write_section(HERE / "bundle.md", "large", "\n".join(lines))


def ceres_section(repeats: int = 3) -> list[str]:
    """The comparison with Ceres (see :func:`against_ceres`), as Markdown lines."""
    lines = [
        "### BAL problems: our engine against Ceres Solver, same start, interleaved runs",
        "",
        "Cost = 0.5 sum r^2 (pixels). Ceres: its BAL example (`../shared/peers/ceres-bal`: "
        "Levenberg-Marquardt, DENSE_SCHUR, one thread, its defaults: function tolerance 1e-6, "
        "gradient 1e-10, parameter 1e-8). Ours: analytic Jacobians, points eliminated (reduced "
        "camera system), Levenberg-Marquardt, the default stopping rules (function tolerance "
        "1e-6, then one Gauss-Newton step), at most 100 iterations, the compiled kernels "
        "loaded before the run (numba's cache: once per process, in the whole-process "
        f"column). Runs alternate ours / Ceres, {repeats} pairs; the ratios are CPU time (user "
        "+ sys: on a shared machine the wall time measures the others' load), taken pair by "
        "pair, medians. 'to Ceres' cost' is our CPU time until our cost first fell to Ceres' "
        "final cost, over Ceres' whole solve; the wall-time ratio of the whole solve and the "
        "load average (median of the pairs' starts) are given for reference.",
        "",
        "| problem | Ceres final cost (iterations) | ours final cost (iterations, stopped by) | "
        "Ceres solve CPU s | ours CPU s | ours / Ceres to Ceres' cost | ours / Ceres whole "
        "solve | ours / Ceres whole process | wall ratio, whole solve | load |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    if not ceres_program().is_file():
        return [*lines, "| (no Ceres program at $CERES_BAL) | | | | | | | | | |", ""]
    per_pair = []
    for name in PROBLEMS:
        path = BAL / name
        if not path.is_file():
            lines.append(f"| {name} | missing | | | | | | | | |")
            continue
        r = against_ceres(path, repeats)
        o, c = r["pairs"][0]["ours"], r["pairs"][0]["ceres"]
        cs = float(np.median([p["ceres"]["solve_cpu_s"] for p in r["pairs"]]))
        os_ = float(np.median([p["ours"]["cpu_seconds"] for p in r["pairs"]]))
        lines.append(
            f"| {name} | {c['final_cost']:.2f} ({c['iterations']}) | {o['final']:.2f} "
            f"({o['iterations']}, {o['termination']}) | {cs:.2f} | {os_:.2f} | "
            f"{r['to_cost']:.2f} | {r['whole']:.2f} | {r['process']:.2f} | {r['wall']:.2f} | "
            f"{r['load']:.1f} |"
        )
        print(lines[-1], flush=True)
        per_pair.append(
            f"{name}: to Ceres' cost "
            + ", ".join(f"{p['to_cost']:.2f}" for p in r["pairs"])
            + "; whole solve "
            + ", ".join(f"{p['whole']:.2f}" for p in r["pairs"])
            + "; final costs "
            + ", ".join(f"{p['ours']['final']:.2f}" for p in r["pairs"])
            + "."
        )
    return [*lines, "", "Pair by pair (ours / Ceres, CPU): " + " ".join(per_pair), ""]


def write_section(path: Path, name: str, text: str) -> None:
    """Replace the section ``name`` of a Markdown file (between HTML comment markers)."""
    begin, end = f"<!-- {name} begin -->", f"<!-- {name} end -->"
    old = path.read_text(encoding="utf-8") if path.is_file() else "# Bundle adjustment\n"
    block = f"{begin}\n{text}\n{end}"
    if begin in old and end in old:
        new = old[: old.index(begin)] + block + old[old.index(end) + len(end) :]
    else:
        new = old.rstrip() + "\n\n" + block + "\n"
    path.write_text(new, encoding="utf-8")


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "ours":
        print(ours_json(Path(sys.argv[2])), flush=True)
    else:
        main(sys.argv[1] if len(sys.argv) > 1 else "all", *(int(a) for a in sys.argv[2:3]))
