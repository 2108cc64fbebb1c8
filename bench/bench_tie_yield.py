"""Yield and precision of the tie points on real kite images, against COLMAP (bench/matching.md,
"Tie points: yield against COLMAP").

Images: 6 overlapping photos of ../shared/data/odm-copr-kap-gcp (2136 x 1424 px), all 15 pairs.
Ours: :func:`lidarphoto.core.photo.tie_points.tie_points` in this process (read, detect,
match, tracks, refinement), the defaults except the pairs (all) and what a variant changes;
CPU = user + sys of this process over the run (numba's compilation excluded: a warm-up run of
two images comes first). Per variant: keypoints, verified pairs, verified matches (the
inliers summed over the pairs), tracks seen in >= 3 images, tracks dropped for two points in
one image, and the stage counts summed over the pairs (after the ratio test, after the mutual
check, after RANSAC + coherence).

COLMAP (with ``--colmap PYTHON``, a Python with pycolmap; never a project dependency):
../shared/peers/colmap-tiepoints/colmap_tp.py on the same images (CPU SIFT, exhaustive
matching, two-view verification at 2 px) in a child process, CPU = the child's user + sys;
its tracks are built from its verified matches by the same union-find.

Precision: per pair, one "common" fundamental matrix fitted (LMedS) to the matches of every
run of this invocation together; each run's median distance of its measurements (ours: the
measurement pairs of every track, refined when the refinement is on; COLMAP: its verified
keypoint matches) to the common epipolar lines (mean of the two images' distances).

Usage: OMP_NUM_THREADS=1 nice -n 10 python bench/bench_tie_yield.py [--variants default,...]
[--colmap /path/to/python] [--colmap-features 8192] [--no-warmup]

The CPU of each stage (``stages_s``: detection and description, matching with the
verification and the tracks, the least-squares refinement) is read at the chain's progress
marks. For a whole-process comparison (interpreter start, imports and numba's cached kernel
included, as for COLMAP's child) run one variant with ``--no-warmup`` and time the process
and ``colmap_tp.py`` alternately from outside (e.g. ``/usr/bin/time -v``); ``--timing`` leaves
out the bench's own precision fit (one F per pair over all runs: a measurement, not a step of
the tie points).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
DATA = HERE.parent.parent / "shared" / "data" / "odm-copr-kap-gcp" / "images"
PEER = HERE.parent.parent / "shared" / "peers" / "colmap-tiepoints" / "colmap_tp.py"
NAMES = ("IMG_0031", "IMG_0034", "IMG_0037", "IMG_0043", "IMG_0046", "IMG_0049")
#: Variants: option changes from the defaults (a name may combine several with "+").
VARIANTS = {
    "default": {},
    "nofine": {"refine": False},
    "f8192": {"max_features": 8192},
    "c01": {"contrast": 0.01},
    "c02": {"contrast": 0.02},
    "c04": {"contrast": 0.04},
    "c005": {"contrast": 0.005},
    "f12k": {"max_features": 12288},
    "f16k": {"max_features": 16384},
    "f24k": {"max_features": 24576},
    "resp": {"keep": "response"},
    "scale": {"keep": "scale"},
    "root": {"root_sift": True},
    "guided": {"guided": True},
    "noroot": {"root_sift": False},
    "noguided": {"guided": False},
    "f4000": {"max_features": 4000},
    "r09": {"ratio": 0.9},
    "nomutual": {"mutual": False},
    "ransac4": {"ransac_px": 4.0},
    "nocoh": {"coherence": 0.0},
    "half": {"max_dimension_px": 1068},
    "nopre": {"preemptive": 0.0},
    "k32": {"checks": 32},
    "k24": {"checks": 24},
    "k64": {"checks": 64},
    "dropun": {"refine_keep_unrefined": False},
    "keepun": {"refine_keep_unrefined": True},
    # the defaults before 2026-12-04 (4,000 features, contrast 0.02, up to 3,000 px, 64 checks,
    # measurements the LSM refused kept at their keypoints)
    "old": {
        "max_features": 4000,
        "contrast": 0.02,
        "max_dimension_px": 3000,
        "checks": 64,
        "refine_keep_unrefined": True,
    },
}


def cpu(who: int = resource.RUSAGE_SELF) -> float:
    """User + sys CPU seconds of this process (or its waited-for children)."""
    r = resource.getrusage(who)
    return r.ru_utime + r.ru_stime


def options_of(name: str):
    """TiePointOptions of a variant name such as ``f8192+c01``."""
    from lidarphoto.core.photo.tie_options import TiePointOptions

    change: dict = {"pair_mode": "all"}
    for part in name.split("+"):
        change.update(VARIANTS[part])
    return dataclasses.replace(TiePointOptions(), **change)


def run_ours(files: list[Path], options) -> tuple[dict, dict]:
    """One tie-point run: (figures, {(i, j): (pa, pb)} measurement pairs of the tracks)."""
    from lidarphoto.core.io.images import read_gray
    from lidarphoto.core.photo.tie_points import detect_features, tie_points

    ids = [f.stem for f in files]
    marks: dict[str, float] = {}
    edges = (0.4, 0.8) if options.refine else (0.5, 1.0)

    def progress(x: float) -> None:  # CPU at the ends of detection and of matching
        for name, edge in zip(("detect_s", "match_s"), edges):
            if x >= edge - 1e-9 and name not in marks:
                marks[name] = cpu()

    t0 = cpu()
    res = tie_points(ids, lambda k: detect_features(read_gray(files[k]), ids[k], options),
                     options, load_image=lambda k: read_gray(files[k], 1),
                     progress=progress)  # fmt: skip
    t = cpu() - t0
    stages = {"detect_s": round(marks["detect_s"] - t0, 1),
              "match_s": round(marks["match_s"] - marks["detect_s"], 1)}  # fmt: skip
    if options.refine:
        stages["refine_s"] = round(t0 + t - marks["match_s"], 1)
    kept = [p for p in res.pairs if p.kept]
    lengths = res.tracks.lengths()
    fig = {"cpu_s": round(t, 1), "keypoints": int(sum(res.features)),
           "pairs": f"{len(kept)} of {len(res.pairs)}",
           "ratio": int(sum(p.n_ratio for p in res.pairs)),
           "mutual": int(sum(p.n_mutual for p in res.pairs)),
           "verified": int(sum(p.n_inliers for p in kept)),
           "tracks3": int((lengths >= 3).sum()), "tracks": int(lengths.size),
           "dropped_two_in_one_image": int(res.tracks.rejected_inconsistent),
           "stages_s": stages}  # fmt: skip
    return fig, track_pairs(res.tracks)


def track_pairs(tracks) -> dict:
    """Every pair of measurements of one track, grouped by image pair (i < j)."""
    out: dict = {}
    starts = np.flatnonzero(np.r_[True, tracks.track[1:] != tracks.track[:-1]])
    ends = np.r_[starts[1:], tracks.track.size]
    for s, e in zip(starts, ends):
        for a in range(s, e):
            for b in range(a + 1, e):
                key = (int(tracks.image[a]), int(tracks.image[b]))
                out.setdefault(key, []).append((tracks.pixels[a], tracks.pixels[b]))
    return {k: (np.array([x for x, _ in v]), np.array([y for _, y in v])) for k, v in out.items()}


def run_colmap(python: str, files: list[Path], nfeat: int) -> tuple[dict, dict]:
    """COLMAP's figures and verified matches, in the same form as :func:`run_ours`."""
    from lidarphoto.core.photo.tie_data import ImageFeatures, PairMatch
    from lidarphoto.core.photo.tie_tracks import build_tracks

    with tempfile.TemporaryDirectory() as tmp:
        imgdir = Path(tmp) / "images"
        imgdir.mkdir()
        for f in files:
            os.symlink(f, imgdir / f.name)
        t0 = cpu(resource.RUSAGE_CHILDREN)
        out = subprocess.run(["nice", "-n", "10", python, str(PEER), f"{tmp}/db.db", str(imgdir),
                              "2", f"{tmp}/out.npz", str(nfeat)],
                             capture_output=True, text=True, check=True)  # fmt: skip
        t = cpu(resource.RUSAGE_CHILDREN) - t0
        z = np.load(f"{tmp}/out.npz")
        row = {f.name: k for k, f in enumerate(files)}
        kp = [z[f"kp_{f.name}"].astype(float) for f in files]
        feats = [
            ImageFeatures(
                f.stem,
                (0, 0),
                1,
                kp[k],
                np.ones(len(kp[k]), np.float32),
                np.zeros((len(kp[k]), 1), np.uint8),
            )
            for k, f in enumerate(files)
        ]
        pairs, matches = [], {}
        for key in z.files:
            if not key.startswith("m_"):
                continue
            a, b = key[2:].split("|")
            i, j, m = row[a], row[b], z[key].astype(np.intp)
            if i > j:
                i, j, m = j, i, m[:, ::-1]
            pairs.append(PairMatch(i, j, m[:, 0], m[:, 1], 0, 0, len(m), np.zeros(0), "ok"))
            matches[(i, j)] = (kp[i][m[:, 0]], kp[j][m[:, 1]])
    tracks = build_tracks(feats, pairs, 2)
    lengths = tracks.lengths()
    info = json.loads(out.stdout.strip().splitlines()[-1])
    fig = {"cpu_s": round(t, 1), "keypoints": int(sum(len(k) for k in kp)),
           "pairs": f"{len(pairs)} of 15", "verified": int(sum(p.n_inliers for p in pairs)),
           "tracks3": int((lengths >= 3).sum()), "tracks": int(lengths.size),
           "dropped_two_in_one_image": int(tracks.rejected_inconsistent),
           "phases_s": {k: round(v, 1) for k, v in info.items() if k.endswith("_s")}}  # fmt: skip
    return fig, matches


def common_epipolar(runs: dict[str, dict]) -> dict[str, float]:
    """Median distance of each run's matches to the epipolar lines of one F per pair fitted
    (LMedS) to all runs' matches of that pair together."""
    import cv2
    from lidarphoto.core.photo.tie_points import epipolar_distances

    keys = sorted({k for m in runs.values() for k in m})
    dist: dict[str, list] = {name: [] for name in runs}
    for key in keys:
        pa = np.vstack([m[key][0] for m in runs.values() if key in m])
        pb = np.vstack([m[key][1] for m in runs.values() if key in m])
        if len(pa) < 50:
            continue
        cv2.setRNGSeed(1)
        f, _ = cv2.findFundamentalMat(pa, pb, cv2.FM_LMEDS)
        if f is None or f.shape != (3, 3):
            continue
        for name, m in runs.items():
            if key in m:
                dist[name].append(epipolar_distances(f, *m[key]))
    return {n: round(float(np.median(np.concatenate(d))), 3) if d else float("nan")
            for n, d in dist.items()}  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--variants", default="default")
    ap.add_argument("--colmap", help="a Python with pycolmap (the peer)")
    ap.add_argument("--colmap-features", type=int, default=8192)
    ap.add_argument("--timing", action="store_true",
                    help="no precision figure (common F): a whole-process timing run")  # fmt: skip
    ap.add_argument("--no-warmup", action="store_true",
                    help="no warm-up run (the whole process timed from outside)")  # fmt: skip
    a = ap.parse_args()
    files = [DATA / f"{n}.jpg" for n in NAMES]
    if not a.no_warmup:
        run_ours(files[:2], options_of("default"))  # warm-up: numba's LSM kernel loaded
    figures, matches = {}, {}
    for name in a.variants.split(","):
        figures[name], matches[name] = run_ours(files, options_of(name))
        print(name, json.dumps(figures[name]), flush=True)
    if a.colmap:
        name = f"colmap{a.colmap_features}"
        figures[name], matches[name] = run_colmap(a.colmap, files, a.colmap_features)
        print(name, json.dumps(figures[name]), flush=True)
    for name, d in ({} if a.timing else common_epipolar(matches)).items():
        print(f"{name}: median epipolar distance to the common F {d} px")
    sys.stdout.flush()


if __name__ == "__main__":
    main()
