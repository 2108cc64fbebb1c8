"""Tie points of a synthetic UAV block of 12-Mpx images: time, memory, tracks, accuracy against
the truth, and a plain OpenCV pipeline as the peer (bench/matching.md, "Tie points").

The block: the simulated UAV block (core/simulation/uav_block.py) with the nominal Canon IXUS
120 (4000 x 3000 px, GSD 5.8 cm at 188 m), ``--strips`` strips of ``--per-strip`` images
(70 % forward, 60 % side overlap), no lens distortion, rendered over a non-repeating texture
(core/simulation/textured_block.py) and written as grey JPEGs (quality 92) to a temporary
folder (generated on the fly, deleted at the end unless --keep).

Ours: the command line ``lidarphoto tiepoints`` in a child process (what the user waits for:
read + detect + match + write), defaults (SIFT, detection at half size, 4,000 features, EO
footprint pairs); wall time and the child's peak RSS. Peer (same session, a subset of
``--peer-images`` images since all pairs at full size take minutes per image): plain OpenCV
as a tutorial writes it: SIFT at full resolution (4,000 features), all pairs, brute-force
k = 2 matching with Lowe's ratio 0.8, cv2.findFundamentalMat RANSAC 2 px, >= 15 inliers;
the same track building; ours is run on the same subset.

Accuracy: each measurement against the projection of its track's true ground point (the
median of the exact ground points of the track's measurements), pixels; a measurement more
than 3 px off is wrong.

The defaults refine every measurement by least-squares matching (since 2026-12-02); with
``--refine`` ours is also run without it (``--refine false``, the keypoints as detected) on
the whole block: the refinement's cost is the difference of the two runs' times.

Usage: python bench/bench_tie_points.py [--strips 10 --per-strip 10 --peer-images 12 --orb
--refine --no-peer]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np
from lidarphoto.core.geometry.collinearity import project_with_status
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.observations import read_observations_csv
from lidarphoto.core.io.orientation import write_eo_csv
from lidarphoto.core.photo.tie_points import ImageFeatures, PairMatch, build_tracks
from lidarphoto.core.simulation.textured_block import (
    TexturedBlock,
    ground_of_pixels,
    make_texture,
    render_view,
)
from lidarphoto.core.simulation.uav_block import simulate_uav_block


def truth_errors(tb, image_ids, obs_img, track, pixels):
    ids = list(tb.block.eo_true.image_id)
    img = np.array([ids.index(image_ids[i]) for i in obs_img])
    ground = np.zeros((len(img), 3))
    for k in np.unique(img):
        sel = img == k
        ground[sel] = ground_of_pixels(tb, pixels[sel], k)
    local = tb.local.map_to_enu(ground)
    order = np.argsort(track, kind="stable")
    t_sorted = track[order]
    starts = np.flatnonzero(np.r_[True, t_sorted[1:] != t_sorted[:-1]])
    med = np.array([np.median(g, axis=0) for g in np.split(local[order], starts[1:])])
    tid = np.searchsorted(t_sorted[starts], track)
    err = np.zeros(len(img))
    for k in np.unique(img):
        sel = np.flatnonzero(img == k)
        px, _, _ = project_with_status(med[tid[sel]], tb.eo_local[k], tb.block.true_camera)
        err[sel] = np.hypot(*(px - pixels[sel]).T)
    bad_tracks = np.unique(track[err > 3.0]).size
    return err, bad_tracks


def run_ours(files, folder, tag, eo, cam, height, extra=()):
    out = folder / f"{tag}.csv"
    args = [sys.executable, "-m", "lidarphoto", "tiepoints", "--images", *map(str, files),
            "--eo", str(eo), "--camera", str(cam), "--height", str(height),
            "--output-observations", str(out), "--output-pairs",
            str(folder / f"{tag}_pairs.csv"), *extra]  # fmt: skip
    ru0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    r = subprocess.run(args, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode:
        raise SystemExit(r.stderr[-3000:])
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (ru.ru_utime - ru0.ru_utime) + (ru.ru_stime - ru0.ru_stime)
    print(r.stdout.strip())
    # ru_maxrss of the children is the largest of any child so far: runs go from the
    # largest block down, so it is this run's unless an earlier run was larger
    return out, wall, cpu, ru.ru_maxrss / 1024.0


def run_peer(files):
    """Plain OpenCV: full-resolution SIFT, all pairs, BF + ratio, F-RANSAC."""
    t0 = time.perf_counter()
    c0 = time.process_time()
    sift = cv2.SIFT_create(4000)
    feats = []
    for f in files:
        img = cv2.imread(str(f), cv2.IMREAD_GRAYSCALE)
        kp, d = sift.detectAndCompute(img, None)
        px = np.array([k.pt for k in kp]) + 0.5
        feats.append(ImageFeatures(f.stem, (img.shape[1], img.shape[0]), 1, px,
                                   np.ones(len(kp), np.float32), d))  # fmt: skip
    t_det = time.perf_counter() - t0
    bf = cv2.BFMatcher(cv2.NORM_L2)
    matches = []
    for i in range(len(files)):
        for j in range(i + 1, len(files)):
            knn = bf.knnMatch(feats[i].descriptors, feats[j].descriptors, k=2)
            good = [m[0] for m in knn if len(m) == 2 and m[0].distance < 0.8 * m[1].distance]
            e = np.zeros(0, np.intp)
            if len(good) < 15:
                matches.append(PairMatch(i, j, e, e, len(good), 0, 0, np.zeros(0), "few"))
                continue
            a = np.array([m.queryIdx for m in good])
            b = np.array([m.trainIdx for m in good])
            _, mask = cv2.findFundamentalMat(feats[i].pixels[a], feats[j].pixels[b],
                                             cv2.FM_RANSAC, 2.0, 0.999)  # fmt: skip
            keep = mask.ravel().astype(bool) if mask is not None else np.zeros(len(a), bool)
            # plain pipelines keep many-to-one matches; the tracks reject them when they clash
            ok = keep.sum() >= 15
            matches.append(PairMatch(i, j, a[keep] if ok else e, b[keep] if ok else e,
                                     len(good), len(good), int(keep.sum()), np.zeros(0),
                                     "ok" if ok else "few"))  # fmt: skip
    tracks = build_tracks(feats, matches, 2)
    return (tracks, time.perf_counter() - t0, time.process_time() - c0, t_det,
            sum(m.kept for m in matches), len(matches))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--strips", type=int, default=10)
    ap.add_argument("--per-strip", type=int, default=10)
    ap.add_argument("--peer-images", type=int, default=12)
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--no-peer", action="store_true", help="ours only")
    ap.add_argument("--orb", action="store_true", help="also run ours with ORB")
    ap.add_argument("--refine", action="store_true",
                    help="also run ours without the least-squares refinement (--refine false)")
    a = ap.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="bench_tie_"))
    print("load:", os.getloadavg(), "folder:", folder)
    t0 = time.perf_counter()
    blk = simulate_uav_block("none", seed=5, n_tie=10, strips=(a.per_strip,) * a.strips,
                             true_focal_mm=5.0, true_x0_mm=0.0, true_y0_mm=0.0)  # fmt: skip
    tb = TexturedBlock.of(blk)
    tex = make_texture(tb.extent(), 0.1, seed=7)
    print(f"texture {tex.values.shape} in {time.perf_counter() - t0:.1f} s")
    images = folder / "images"
    images.mkdir()
    files = []
    for k, name in enumerate(blk.eo_true.image_id):
        f = images / f"{name}.jpg"
        cv2.imwrite(str(f), render_view(tb, tex, k), [cv2.IMWRITE_JPEG_QUALITY, 92])
        files.append(f)
    del tex
    mb = sum(f.stat().st_size for f in files) / 1e6
    print(f"{len(files)} images rendered in {time.perf_counter() - t0:.1f} s ({mb:.0f} MB)")
    eo, cam = folder / "eo.csv", folder / "camera.json"
    write_eo_csv(eo, blk.eo_dg)
    write_camera_json(cam, blk.camera)
    h = blk.config.ground_height_m
    rows = []

    def ours(tag, subset, extra=()):
        out, wall, cpu, rss = run_ours(subset, folder, tag, eo, cam, h, extra)
        obs = read_observations_csv(out)
        ids = sorted(set(obs.image_id))
        _, track = np.unique(obs.point_id, return_inverse=True)
        img = np.array([ids.index(i) for i in obs.image_id])
        err, bad = truth_errors(tb, ids, img, track, obs.pixels)
        with open(folder / f"{tag}_pairs.csv") as fh:
            pr = fh.read().splitlines()[1:]
        kept = sum(line.endswith(",ok") for line in pr)
        rows.append({"run": tag, "images": len(subset), "s": wall, "cpu_s": cpu,
                     "peak_rss_mb": rss,
                     "pairs": f"{kept}/{len(pr)}", "tracks": int(track.max() + 1),
                     "measurements": len(obs), "median_px": float(np.median(err)),
                     "p95_px": float(np.percentile(err, 95)),
                     "wrong_meas_pct": 100 * float(np.mean(err > 3)),
                     "wrong_tracks_pct": 100 * bad / (track.max() + 1)})  # fmt: skip
        print(rows[-1])

    ours("ours_sift", files)
    if a.refine:
        ours("ours_sift_keypoints", files, ("--refine", "false"))
    if a.orb:
        ours("ours_orb", files, ("--detector", "orb", "--max-dimension", "0"))
    sub = files[: a.peer_images]
    if not a.no_peer:  # ours on the peer's subset
        ours("ours_sift_subset", sub)
    if a.no_peer:
        print(json.dumps(rows, indent=1))
        if not a.keep:
            shutil.rmtree(folder)
        return
    tracks, wall, cpu, t_det, kept, tried = run_peer(sub)
    ids = [f.stem for f in sub]
    err, bad = truth_errors(tb, ids, tracks.image, tracks.track, tracks.pixels)
    rows.append({"run": "peer_opencv_allpairs_subset", "images": len(sub), "s": wall,
                 "cpu_s": cpu,
                 "peak_rss_mb": float("nan"), "pairs": f"{kept}/{tried}",
                 "tracks": tracks.n_tracks, "measurements": int(tracks.track.size),
                 "median_px": float(np.median(err)), "p95_px": float(np.percentile(err, 95)),
                 "wrong_meas_pct": 100 * float(np.mean(err > 3)),
                 "wrong_tracks_pct": 100 * bad / max(tracks.n_tracks, 1),
                 "detect_s": t_det})  # fmt: skip
    print(rows[-1])
    print("load:", os.getloadavg())
    print(json.dumps(rows, indent=1))
    if not a.keep:
        shutil.rmtree(folder)


if __name__ == "__main__":
    main()
