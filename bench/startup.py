"""Whole-process times of the command line: ``lidarphoto --help``, ``lidarphoto <alg> --help``
and ``lidarphoto groundfilter`` on a 10 M-point LAZ against laspy's own read + write of that
file (``python -c`` reading it with laspy and writing it back), each a fresh process as a user
or a batch script starts it. Runs are interleaved (one of each command per round) and the
medians reported with the machine's load average; with ``--before DIR`` (a checkout of the
code before, e.g. ``git worktree add DIR <commit>``) the same commands run on that code too.

    python bench/startup.py [--runs 7] [--laz FILE] [--before DIR] [--json FILE]

Without ``--laz`` the AHN3 x12 file (10.2 M points) is built as bench/bench_ground_filter.py
builds it, in a temporary folder. Results: bench/startup.md.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HELP = ("--help", "groundfilter --help", "extractroofplanes --help", "tiepoints --help",
        "bundleadjustment --help")  # fmt: skip
LASPY = "import sys, laspy; laspy.read(sys.argv[1]).write(sys.argv[2])"


def _env(tree: Path | None) -> dict[str, str]:
    """The environment that imports ``lidarphoto`` from ``tree`` (its parent on the path)."""
    env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "1"))
    if tree is not None:
        env["PYTHONPATH"] = str(tree.parent)
    return env


def _timed(argv: list[str], env: dict[str, str]) -> tuple[float, float]:
    """(wall, CPU) seconds of one process (CPU: user + system of the child)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    run = subprocess.run(argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if run.returncode != 0:
        raise SystemExit(f"{' '.join(argv)}: exit {run.returncode}\n{run.stderr.decode()[-2000:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def commands(laz: Path | None, out: Path, before: Path | None, helps=HELP) -> dict[str, tuple]:
    """{label: (argv, env)} of every process measured."""
    trees = {"": None} if before is None else {"": None, " (before)": before}
    cmds: dict[str, tuple] = {}
    for suffix, tree in trees.items():
        env = _env(tree)
        for words in helps:
            cmds[f"lidarphoto {words}{suffix}"] = (
                [sys.executable, "-m", "lidarphoto", *words.split()], env)
        if laz is not None:
            cmds[f"lidarphoto groundfilter{suffix}"] = (
                [sys.executable, "-m", "lidarphoto", "groundfilter", "--input", str(laz),
                 "--output-cloud", str(out / f"ground{suffix.strip(' ()')}.laz")], env)
    if laz is not None:
        cmds["laspy read + write"] = ([sys.executable, "-c", LASPY, str(laz),
                                       str(out / "laspy.laz")], _env(None))
    return cmds  # fmt: skip


def measure(cmds: dict[str, tuple], runs: int) -> dict[str, dict]:
    """Interleaved rounds: every command once per round; medians, min and max."""
    times: dict[str, list[tuple[float, float]]] = {k: [] for k in cmds}
    loads = [os.getloadavg()[0]]
    for k in range(runs):
        for label, (argv, env) in cmds.items():
            times[label].append(_timed(argv, env))
            print(f"round {k + 1}: {label}: {times[label][-1][0]:.2f} s wall, "
                  f"{times[label][-1][1]:.2f} s CPU", file=sys.stderr, flush=True)
        loads.append(os.getloadavg()[0])
    out = {}
    for label, pairs in times.items():
        wall = [w for w, _ in pairs]
        cpu = [c for _, c in pairs]
        out[label] = {"wall_median": statistics.median(wall), "wall_min": min(wall),
                      "wall_max": max(wall), "cpu_median": statistics.median(cpu)}  # fmt: skip
    out["load"] = {"min": min(loads), "max": max(loads)}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--laz", type=Path, help="the 10 M-point LAZ (default: AHN3 x12, built)")
    ap.add_argument("--no-groundfilter", action="store_true", help="the help commands only")
    ap.add_argument("--no-help", action="store_true", help="the groundfilter run only")
    ap.add_argument("--before", type=Path, help="the plugin folder of the code before")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        laz = args.laz
        if laz is None and not args.no_groundfilter:
            sys.path.insert(0, str(ROOT / "bench"))
            from bench_ground_filter import build_ahn3

            laz = build_ahn3(Path(tmp), (3, 4))
        cmds = commands(None if args.no_groundfilter else laz, Path(tmp), args.before,
                        () if args.no_help else HELP)  # fmt: skip
        result = measure(cmds, args.runs)
    load = result.pop("load")
    print(f"{args.runs} interleaved runs, load average {load['min']:.1f}-{load['max']:.1f}")
    for label, r in result.items():
        print(f"{label:45s} wall {r['wall_median']:6.2f} s (min {r['wall_min']:.2f}, "
              f"max {r['wall_max']:.2f})  CPU {r['cpu_median']:6.2f} s")  # fmt: skip
    if "laspy read + write" in result:
        ref = result["laspy read + write"]
        for label in [k for k in result if k.startswith("lidarphoto groundfilter")
                      and "--help" not in k]:  # fmt: skip
            r = result[label]
            print(f"{label} / laspy: wall {r['wall_median'] / ref['wall_median']:.2f}x, "
                  f"CPU {r['cpu_median'] / ref['cpu_median']:.2f}x")
    if args.json:
        args.json.write_text(json.dumps({"load": load, **result}, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
