"""Real COLMAP models for tests/core/test_colmap_real.py, made by COLMAP itself (pycolmap).

Runs in a Python with pycolmap (4.2.1 here), numpy and opencv-python-headless, never a
project dependency::

    python3 -m venv ~/pycolmap-venv
    ~/pycolmap-venv/bin/pip install pycolmap numpy opencv-python-headless
    OMP_NUM_THREADS=1 ~/pycolmap-venv/bin/python bench/colmap_real.py make \
        --images ../shared/data/odm-copr-kap-gcp/images

``make``: six kite photos of odm-copr-kap-gcp (CC BY-SA 4.0, Tobias & Mandel /
OpenDroneMap; IMG_0031 ... 0049, 2136 x 1424 px) are downscaled to 1000 x 667 px
(cv2.INTER_AREA) in a temporary folder, and for each camera model (SIMPLE_RADIAL, OPENCV with
its principal point refined, OPENCV_FISHEYE) COLMAP extracts SIFT features (CPU, at most
4096 per image), matches all pairs, verifies them and runs its incremental mapper with one
camera for the six images (OPENCV_FISHEYE: from a prior, see PRIOR, held while mapping, then
refined by one global bundle adjustment). The largest model is trimmed to at most 250 3D
points (a random choice, seed 0) through pycolmap's API: a new
:class:`pycolmap.Reconstruction` gets COLMAP's camera, each image's pose (``cam_from_world``),
the kept points (COLMAP's xyz, colour; ids renumbered 1..N by COLMAP) and their tracks with
the keypoints they observe (COLMAP's keypoint positions) plus the first 5 untracked keypoints
of each image, and COLMAP recomputes the points' errors (``update_point_3d_errors``). It is
written by COLMAP's own writers, ``write_text`` into ``tests/data/colmap/<MODEL>/txt`` and,
for OPENCV, ``write_binary`` into ``.../bin``. Every number in the files is COLMAP's; only
the set of points and keypoints is cut.

Next to them, ``projections.csv``: 200 (3D point, image) pairs (seed 1) drawn among all in
front of the camera and inside the frame, tracked or not, with COLMAP's projection
``camera.img_from_cam(image.cam_from_world() * xyz)``; and ``grid.csv``: COLMAP's projection
of camera-frame points (x right, y down, z forward) on a 9 x 7 grid of normalised
coordinates spanning 1.2 times the frame (the whole distortion field). Both are written with
17 significant digits. ``record.json``: pycolmap's version, the reconstruction summary
(images, points, observations, COLMAP's mean reprojection error before and after the trim),
the camera parameters and the file sizes.

``check-export``: reads a model written by the project's ``exportcolmap`` (text) with
pycolmap and projects the recorded pairs through it, against COLMAP's recorded projections
(matched by image name; the points are the original's), lets COLMAP recompute the points'
errors on it (the export writes 0) and records the result under ``export_checks`` in
record.json, e.g.::

    lidarphoto importcolmap --input tests/data/colmap/OPENCV/txt --frame LOCAL \
        --output-camera c.json --output-eo eo.csv --output-observations o.csv \
        --output-points p.csv
    lidarphoto exportcolmap --camera c.json --eo eo.csv --observations o.csv --points p.csv \
        --output-folder out
    ~/pycolmap-venv/bin/python bench/colmap_real.py check-export --model OPENCV out
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np
import pycolmap

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "tests" / "data" / "colmap"
IMAGES = ("IMG_0031.jpg", "IMG_0034.jpg", "IMG_0037.jpg", "IMG_0043.jpg", "IMG_0046.jpg",
          "IMG_0049.jpg")  # fmt: skip
MODELS = ("SIMPLE_RADIAL", "OPENCV", "OPENCV_FISHEYE")
WIDTH = 1000
N_POINTS = 250
N_UNTRACKED = 5
#: COLMAP refuses fisheye pairs without a focal length prior: the nominal focal length of
#: ../shared/data/odm-copr-kap-gcp/camera.json, 2873 px at 2136 px wide, is 1345 px at WIDTH;
#: k1..k4 start from tan's series (1/3, 2/15, 17/315, 62/2835: an equidistant model of this
#: perspective lens), else the frame's edges fail the two-view verification.
PRIOR = {"OPENCV_FISHEYE": "1345,1345,500,333.5,0.333333,0.133333,0.053968,0.021869"}
#: The models also written in COLMAP's binary format (the files are kept under 300 KB).
BINARY = ("OPENCV",)
N_PAIRS = 200


def downscale(src: Path, dst: Path) -> tuple[int, int]:
    """The six photos at WIDTH px wide (INTER_AREA) in ``dst``; returns (width, height)."""
    dst.mkdir(parents=True, exist_ok=True)
    size = (0, 0)
    for name in IMAGES:
        img = cv2.imread(str(src / name), cv2.IMREAD_COLOR)
        if img is None:
            sys.exit(f"cannot read {src / name}")
        h = round(img.shape[0] * WIDTH / img.shape[1])
        small = cv2.resize(img, (WIDTH, h), interpolation=cv2.INTER_AREA)
        cv2.imwrite(str(dst / name), small, [cv2.IMWRITE_JPEG_QUALITY, 95])
        size = (WIDTH, h)
    return size


def reconstruct(images: Path, work: Path, model: str) -> pycolmap.Reconstruction:
    """COLMAP's features, exhaustive matching and incremental mapping; the largest model."""
    db = work / f"{model}.db"
    pycolmap.set_random_seed(0)
    reader = pycolmap.ImageReaderOptions()
    reader.camera_model = model
    if model in PRIOR:
        reader.camera_params = PRIOR[model]
    ext = pycolmap.FeatureExtractionOptions()
    ext.sift.max_num_features = 4096
    pycolmap.extract_features(db, images, camera_mode=pycolmap.CameraMode.SINGLE,
                              reader_options=reader, extraction_options=ext,
                              device=pycolmap.Device.cpu)  # fmt: skip
    pycolmap.match_exhaustive(db, device=pycolmap.Device.cpu)
    opts = pycolmap.IncrementalPipelineOptions()
    opts.ba_refine_principal_point = model == "OPENCV"
    # the fisheye: mapped with the prior held (its images do not register while the focal
    # length and k1..k4 float on two or three images), then one global bundle adjustment
    # refines the focal lengths and k1..k4 with everything else
    opts.ba_refine_focal_length = opts.ba_refine_extra_params = model not in PRIOR
    out = work / f"{model}_sparse"
    out.mkdir(exist_ok=True)
    recs = pycolmap.incremental_mapping(db, images, out, options=opts)
    if not recs:
        sys.exit(f"{model}: COLMAP made no model")
    rec = max(recs.values(), key=lambda r: (r.num_reg_images(), r.num_points3D()))
    if model in PRIOR:
        ba = pycolmap.BundleAdjustmentOptions()
        ba.refine_focal_length = ba.refine_extra_params = True
        pycolmap.bundle_adjustment(rec, ba)
        rec.update_point_3d_errors()
    return rec


def trimmed(rec: pycolmap.Reconstruction, rng: np.random.Generator) -> pycolmap.Reconstruction:
    """A new reconstruction with COLMAP's cameras and poses, N_POINTS of its points with their
    tracks, the keypoints they observe and N_UNTRACKED untracked keypoints per image."""
    ids = np.array(sorted(rec.point3D_ids()))
    keep = sorted(rng.choice(ids, size=min(N_POINTS, len(ids)), replace=False).tolist())
    new = pycolmap.Reconstruction()
    for cam in rec.cameras.values():
        new.add_camera_with_trivial_rig(cam)
    index = {}  # (image id, old point2D index) -> new point2D index
    for iid in sorted(rec.reg_image_ids()):
        img = rec.image(iid)
        used = sorted(el.point2D_idx for pid in keep for el in rec.point3D(pid).track.elements
                      if el.image_id == iid)  # fmt: skip
        free = [k for k, p in enumerate(img.points2D) if not p.has_point3D()][:N_UNTRACKED]
        order = sorted(used + free)
        xy = np.array([img.points2D[k].xy for k in order], dtype=np.float64).reshape(-1, 2)
        index.update({(iid, k): j for j, k in enumerate(order)})
        image = pycolmap.Image(name=img.name, keypoints=xy, camera_id=img.camera_id,
                               image_id=iid)  # fmt: skip
        new.add_image_with_trivial_frame(image, img.cam_from_world())
    for pid in keep:
        p = rec.point3D(pid)
        track = pycolmap.Track()
        for el in p.track.elements:
            track.add_element(el.image_id, index[(el.image_id, el.point2D_idx)])
        new.add_point3D(p.xyz, track, p.color)
    new.update_point_3d_errors()
    return new


def project(rec: pycolmap.Reconstruction, iid: int, xyz: np.ndarray) -> np.ndarray | None:
    """COLMAP's pixel of a model point in an image (None behind the camera)."""
    img = rec.image(iid)
    return rec.cameras[img.camera_id].img_from_cam(img.cam_from_world() * xyz)


def pairs(rec: pycolmap.Reconstruction, rng: np.random.Generator) -> list[tuple]:
    """N_PAIRS (point, image) pairs in front and inside the frame, with COLMAP's pixel."""
    cand = []
    for pid in sorted(rec.point3D_ids()):
        tracked = {el.image_id for el in rec.point3D(pid).track.elements}
        for iid in sorted(rec.reg_image_ids()):
            px = project(rec, iid, rec.point3D(pid).xyz)
            cam = rec.cameras[rec.image(iid).camera_id]
            if px is not None and 0 <= px[0] <= cam.width and 0 <= px[1] <= cam.height:
                cand.append((pid, iid, int(iid in tracked), float(px[0]), float(px[1])))
    pick = sorted(rng.choice(len(cand), size=min(N_PAIRS, len(cand)), replace=False))
    return [cand[k] for k in pick]


def grid(cam: pycolmap.Camera) -> list[tuple]:
    """COLMAP's pixel of camera-frame points (u, v, 1) on a grid over 1.2 x the frame."""
    fx, fy = cam.focal_length_x, cam.focal_length_y
    cx, cy = cam.principal_point_x, cam.principal_point_y
    rows = []
    for v in np.linspace(-0.1 * cam.height - cy, 1.1 * cam.height - cy, 7) / fy:
        for u in np.linspace(-0.1 * cam.width - cx, 1.1 * cam.width - cx, 9) / fx:
            px = cam.img_from_cam(np.array([u, v, 1.0]))
            rows.append((float(u), float(v), 1.0, float(px[0]), float(px[1])))
    return rows


def write_csv(path: Path, header: tuple, rows: list[tuple]) -> None:
    with path.open("w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(header)
        for r in rows:
            w.writerow([f"{v:.17g}" if isinstance(v, float) else v for v in r])


def make(args: argparse.Namespace) -> None:
    old = OUT / "record.json"
    models = json.loads(old.read_text())["models"] if old.is_file() else {}
    record: dict = {"pycolmap": pycolmap.__version__, "colmap": pycolmap.COLMAP_version,
                    "images": list(IMAGES), "models": models}  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        small = Path(tmp) / "images"
        record["image_size"] = downscale(Path(args.images), small)
        for model in args.models:
            rec = reconstruct(small, Path(tmp), model)
            full = {
                "images": rec.num_reg_images(),
                "points": rec.num_points3D(),
                "observations": rec.compute_num_observations(),
                "mean_reprojection_error_px": rec.compute_mean_reprojection_error(),
            }
            new = trimmed(rec, np.random.default_rng(0))
            folder = OUT / model
            writers = [("txt", new.write_text)]
            if model in BINARY:
                writers.append(("bin", new.write_binary))
            for sub, write in writers:
                (folder / sub).mkdir(parents=True, exist_ok=True)
                write(str(folder / sub))
            write_csv(folder / "projections.csv",
                      ("point3d_id", "image_id", "tracked", "x_px", "y_px"),
                      pairs(new, np.random.default_rng(1)))  # fmt: skip
            cam = next(iter(new.cameras.values()))
            write_csv(folder / "grid.csv", ("xc", "yc", "zc", "x_px", "y_px"), grid(cam))
            record["models"][model] = {
                "full_model": full,
                "trimmed": {"images": new.num_reg_images(), "points": new.num_points3D(),
                            "observations": new.compute_num_observations(),
                            "mean_reprojection_error_px":
                                new.compute_mean_reprojection_error()},
                "camera": {"model": cam.model_name, "width": cam.width, "height": cam.height,
                           "params": [float(v) for v in cam.params]},
                "bytes": {str(p.relative_to(folder)): p.stat().st_size
                          for p in sorted(folder.rglob("*")) if p.is_file()},
            }  # fmt: skip
            print(model, json.dumps(record["models"][model]), flush=True)
            old.write_text(json.dumps(record, indent=1) + "\n")


def check_export(args: argparse.Namespace) -> None:
    """pycolmap reads our exported model: its projections against COLMAP's recorded ones, and
    COLMAP's errors recomputed on it against the original's; recorded in record.json."""
    orig = pycolmap.Reconstruction(str(OUT / args.model / "txt"))
    ours = pycolmap.Reconstruction(str(args.folder))
    by_name = {img.name: iid for iid, img in ours.images.items()}
    diffs = []
    with (OUT / args.model / "projections.csv").open() as fh:
        for row in csv.DictReader(fh):
            iid = int(row["image_id"])
            xyz = orig.point3D(int(row["point3d_id"])).xyz
            px = project(ours, by_name[orig.image(iid).name], xyz)
            diffs.append(np.hypot(px[0] - float(row["x_px"]), px[1] - float(row["y_px"])))
    d = np.array(diffs)
    ours.update_point_3d_errors()  # the export writes ERROR 0: COLMAP recomputes them
    out = {
        "read_by": f"pycolmap {pycolmap.__version__}",
        "cameras": [c.model_name for c in ours.cameras.values()],
        "images": ours.num_reg_images(),
        "points": ours.num_points3D(),
        "observations": ours.compute_num_observations(),
        "pairs": len(d),
        "median_px": float(np.median(d)),
        "max_px": float(np.max(d)),
        "mean_reprojection_error_px": ours.compute_mean_reprojection_error(),
        "original_mean_reprojection_error_px": orig.compute_mean_reprojection_error(),
    }
    print(args.model, json.dumps(out))
    path = OUT / "record.json"
    record = json.loads(path.read_text())
    record.setdefault("export_checks", {})[args.model] = out
    path.write_text(json.dumps(record, indent=1) + "\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    mk = sub.add_parser("make", help="reconstruct, trim, write tests/data/colmap")
    mk.add_argument("--images", required=True, help="odm-copr-kap-gcp/images")
    mk.add_argument("--models", nargs="+", default=list(MODELS))
    ce = sub.add_parser("check-export", help="read an exportcolmap model with pycolmap")
    ce.add_argument("--model", required=True, choices=MODELS)
    ce.add_argument("folder")
    args = ap.parse_args()
    make(args) if args.cmd == "make" else check_export(args)


if __name__ == "__main__":
    main()
