"""The catalogue of bad inputs of the photogrammetric algorithms (orthophotos, mosaics, tie
points, control location, bundle adjustment, camera calibration), kept with
tests/core/test_bad_inputs.py and in its style: every case runs the command line and asserts
the exit code, the one line on stderr with the error that names the parameter or the file
(row), that nothing was written (not even a temporary) and that the inputs are unchanged.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pyproj
import pytest
from lidarphoto.core.cli import main
from lidarphoto.core.geometry.camera import camera_from_dict
from lidarphoto.core.geometry.projection import PROJECTIONS
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.dsm import write_dsm
from lidarphoto.core.io.orientation import write_eo_csv
from lidarphoto.core.io.raster_write import GeoTiffWriter, write_rgb_tiff
from lidarphoto.core.photo.calibration_targets import TargetSpec, target_field
from lidarphoto.core.photo.camera_calibration import fisheye_evidence, simulate_views
from lidarphoto.core.photo.orientation import ExteriorOrientationTable
from lidarphoto.core.simulation.render import RenderOptions, render_image
from test_bad_inputs import _copy, _snapshot
from test_orthophoto import CRS, X0, Y0, _scene

SHARED = Path(__file__).resolve().parents[3] / "shared" / "data"
GSD = 0.06
W, H = 400, 300  # the camera's image size, pixels


# ----------------------------------------------------------------------------- inputs
@pytest.fixture(scope="module")
def block(tmp_path_factory):
    """Two images of a house on sloping ground (tests/core/test_orthophoto.py's scene), with
    their camera, EO table and DSM: the inputs every case copies and spoils."""
    folder = tmp_path_factory.mktemp("block")
    scene, dsm = _scene()
    cam = camera_from_dict({"name": "k1", "focal_mm": 8.0, "pixel_size_mm": 0.01,
                            "width_px": W, "height_px": H})  # fmt: skip
    xyz = np.array([[X0 + 20.0, Y0 + 18.0, 60.0], [X0 + 22.0, Y0 + 19.0, 60.0]])
    opk = np.radians([[2.0, -1.0, 10.0], [-1.0, 2.0, 12.0]])
    eo = ExteriorOrientationTable(("sw", "ne"), np.array([0.0, 1.0]), ("a", "a"), xyz, opk,
                                  pyproj.CRS.from_user_input(CRS).to_wkt())  # fmt: skip
    images = folder / "images"
    images.mkdir()
    for k, name in enumerate(eo.image_id):
        img = render_image(scene, cam, xyz[k], opk[k], RenderOptions(step_px=1, noise_dn=2.0))
        write_rgb_tiff(images / f"{name}.tif", img.rgb)
        cv2.imwrite(str(images / f"{name}.jpg"), img.rgb[:, :, ::-1])
    write_camera_json(folder / "camera.json", cam)
    write_eo_csv(folder / "eo.csv", eo)
    write_dsm(folder / "dsm.tif", dsm)
    assert main(["orthorectify", "--camera", str(folder / "camera.json"), "--eo",
                 str(folder / "eo.csv"), "--images", str(images / "sw.tif"),
                 str(images / "ne.tif"), "--dsm", str(folder / "dsm.tif"), "--crs", CRS,
                 "--gsd", "0.1", "--output-folder", str(folder / "orthos")]) == 0  # fmt: skip
    return folder


def _ortho(b: Path, inp: Path, out: Path, *extra: str, image: Path | None = None,
           eo: Path | None = None) -> list[str]:  # fmt: skip
    """orthorectify on copies of the block's files (image: the one image taken)."""
    (inp / "images").mkdir(exist_ok=True)
    img = image or _copy(b / "images" / "sw.tif", inp / "images")
    return ["orthorectify", "--camera", str(_copy(b / "camera.json", inp)),
            "--eo", str(eo or _copy(b / "eo.csv", inp)), "--images", str(img),
            "--dsm", str(_copy(b / "dsm.tif", inp)), "--crs", CRS, "--gsd", str(GSD),
            "--output-folder", str(out / "orthos"), *extra]  # fmt: skip


def _mosaic(b: Path, inp: Path, out: Path, *names: str) -> list[str]:
    """orthomosaic of the orthophotos named (copied into ``inp``; ``a=b``: b under name a)."""
    paths = []
    for n in names:
        dst, _, src = n.partition("=")
        target = inp / dst
        if not target.exists():
            _copy(b / "orthos" / (src or dst), inp, dst)
        paths.append(str(target))
    return ["orthomosaic", "--orthophotos", *paths, "--output", str(out / "m.tif")]


def _ties(b: Path, inp: Path, out: Path, *images: str, eo: Path | None = None,
          crs: str | None = None) -> list[str]:  # fmt: skip
    """tiepoints on images written in ``inp`` (``name.ext=src``: the pixels of the block's
    image ``src`` saved as name.ext, re-encoded: the same pixels in another file)."""
    folder = _in_images(inp)
    for n in images:
        dst, _, src = n.partition("=")
        rgb = cv2.imread(str(b / "images" / f"{src}.tif"))
        cv2.imwrite(str(folder / dst), rgb)
    argv = ["tiepoints", "--images", str(folder),
            "--output-observations", str(out / "ties.csv")]  # fmt: skip
    if eo is not None:
        argv += ["--eo", str(eo), "--camera", str(_copy(b / "camera.json", inp))]
    return argv + (["--crs", crs] if crs else [])


def _copies(argv: list[str], inp: Path) -> list[str]:
    """The command with two byte copies of images/a.png beside it."""
    for name in ("b.png", "c.png"):
        _copy(inp / "images" / "a.png", inp / "images", name)
    return argv


def _chip(path: Path, xy: tuple[float, float], crs: str = CRS) -> Path:
    """A 31 x 31 chip of 10 cm cells around the point, textured (a seeded pattern)."""
    tex = np.random.default_rng(3).integers(0, 255, (31, 31), dtype=np.uint8)
    gt = (xy[0] - 1.55, 0.1, 0.0, xy[1] + 1.55, 0.0, -0.1)
    with GeoTiffWriter(path, 31, 31, 1, np.uint8, gt, crs, tile=0) as w:
        w.write(tex)
    return path


def _locate(b: Path, inp: Path, out: Path, *images: str, chip_crs: str = CRS,
            eo: Path | None = None, cut_chip: bool = False) -> list[str]:  # fmt: skip
    """locatecontrolpoints on the block (one control point on the ground seen by both
    images); ``name=src@f``: the block's image ``src`` reduced f times, saved as name."""
    folder = _in_images(inp)
    for n in images or ("sw.tif=sw", "ne.tif=ne"):
        dst, _, src = n.partition("=")
        src, _, f = src.partition("@")
        rgb = cv2.imread(str(b / "images" / f"{src}.tif"))
        if f:
            rgb = cv2.resize(rgb, (W // int(f), H // int(f)), interpolation=cv2.INTER_AREA)
        cv2.imwrite(str(folder / dst), rgb)
    (inp / "chips").mkdir()
    xy = (X0 + 21.0, Y0 + 18.5)
    chip = _chip(inp / "chips" / "P1.tif", xy, chip_crs)
    if cut_chip:
        _half(chip, inp / "chips")
    control = inp / "control.csv"
    control.write_text(f"point_id,X,Y,Z\nP1,{xy[0]},{xy[1]},0.7\n", encoding="utf-8")
    return ["locatecontrolpoints", "--chips", str(inp / "chips"), "--control-points",
            str(control), "--camera", str(_copy(b / "camera.json", inp)), "--eo",
            str(eo or _copy(b / "eo.csv", inp)), "--images", str(folder), "--crs", CRS,
            "--output", str(out / "located.csv")]  # fmt: skip


def _link(target: Path) -> Path:
    link = target.parent / "link.tif"
    link.symlink_to(target.name)
    return link


def _eo_lonlat(b: Path, inp: Path) -> Path:
    """The block's EO with X, Y in longitude and latitude (degrees): the wrong table."""
    tr = pyproj.Transformer.from_crs(CRS, "EPSG:4326", always_xy=True)
    lines = (b / "eo.csv").read_text(encoding="utf-8").splitlines()
    rows = [lines[0]]
    for line in lines[1:]:
        c = line.split(",")
        lon, lat = tr.transform(float(c[3]), float(c[4]))
        rows.append(",".join([*c[:3], f"{lon:.8f}", f"{lat:.8f}", *c[5:]]))
    path = inp / "eo.csv"
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return path


def _half(src: Path, folder: Path, name: str | None = None) -> Path:
    """The first half of a file: a download or a copy cut short."""
    dst = folder / (name or src.name)
    raw = src.read_bytes()
    dst.write_bytes(raw[: len(raw) // 2])
    return dst


# ----------------------------------------------------------------------------- the cases
@dataclass(frozen=True)
class Case:
    """A bad input: ``build(block, inp, out)`` writes the inputs and returns argv."""

    id: str
    build: Callable[[Path, Path, Path], list[str]]
    error: str  # regex searched in the one line on stderr
    code: int = 2


def _in_images(inp: Path) -> Path:
    (inp / "images").mkdir(exist_ok=True)
    return inp / "images"


CASES = [
    # -- orthorectify
    Case("extent outside every footprint",
         lambda b, i, o: _ortho(b, i, o, "--extent", "0,0,10,10"),
         r"EXTENT 0,0,10,10 lies outside every image's footprint on the DSM \(the footprints "
         r"span x 850\d\d\.\d+ to 850\d\d\.\d+, y 4470\d\d\.\d+ to 4470\d\d\.\d+\): give the "
         r"extent in the mapping CRS, within the footprints$"),
    Case("inverted extent",
         lambda b, i, o: _ortho(b, i, o, "--extent", "85030,447030,85000,447000"),
         r"EXTENT 85030,447030,85000,447000: give xmin,ymin,xmax,ymax with xmin < xmax and "
         r"ymin < ymax$"),
    Case("EO in longitude and latitude (orthorectify)",
         lambda b, i, o: _ortho(b, i, o, eo=_eo_lonlat(b, i)),
         r"eo\.csv: the perspective centres \(x 4\.3\d+ to 4\.3\d+, y 52\.\d+ to 52\.\d+\) "
         r"looks like longitude and latitude in degrees, not coordinates of 'Amersfoort / RD "
         r"New' \(projected, metre\)$"),
    Case("GSD of a micrometre",
         lambda b, i, o: _ortho(b, i, o)[:-3] + ["1e-6"] + _ortho(b, i, o)[-2:],
         r"GSD 1e-06: the orthophoto of image sw would be \d+ x \d+ cells, beyond what a "
         r"GeoTIFF can hold: give a larger GSD \(0: the images' own\)$"),
    Case("half a JPEG", lambda b, i, o: _ortho(
        b, i, o, image=_half(b / "images" / "sw.jpg", _in_images(i))),
         r"sw\.jpg: truncated JPEG: its image data stop at byte \d+ without the end-of-image "
         r"marker \(a copy or a download cut short\?\)$"),
    # -- orthomosaic
    Case("same orthophoto twice",
         lambda b, i, o: _mosaic(b, i, o, "sw_ortho.tif", "ne_ortho.tif", "sw_ortho.tif"),
         r"ORTHOPHOTOS: \S+/in/sw_ortho\.tif is given twice: one image would count twice; give "
         r"it once$"),
    Case("same orthophoto through a folder and by name",
         lambda b, i, o: _mosaic(b, i, o, "sw_ortho.tif", "ne_ortho.tif")[:-2]
         + [str(i), "--output", str(o / "m.tif")],
         r"ORTHOPHOTOS: \S+/in/ne_ortho\.tif is given twice"),
    Case("an orthophoto and a link to it", lambda b, i, o: _mosaic(
        b, i, o, "sw_ortho.tif", "ne_ortho.tif")[:-2] + [str(_link(i / "sw_ortho.tif")),
                                                       "--output", str(o / "m.tif")],
         r"ORTHOPHOTOS: \S+/in/link\.tif is \S+/in/sw_ortho\.tif again"),
    Case("an orthophoto copied under another name",
         lambda b, i, o: _mosaic(b, i, o, "sw_ortho.tif", "ne_ortho.tif", "copy.tif=sw_ortho.tif"),
         r"ORTHOPHOTOS: \S+/in/copy\.tif has the same content as \S+/in/sw_ortho\.tif \(a "
         r"copy\): one image would count twice; give it once$"),
    Case("a cut orthophoto", lambda b, i, o: _mosaic(b, i, o, "ne_ortho.tif")[:-2]
         + [str(_half(b / "orthos" / "sw_ortho.tif", i)), "--output", str(o / "m.tif")],
         r"sw_ortho\.tif: cannot read the pixels: the file is truncated or corrupt \(.*"
         r"TIFFReadEncodedTile\(\) failed"),
    # -- tiepoints
    Case("three copies of one image", lambda b, i, o: _copies(_ties(b, i, o, "a.png=sw"), i),
         r"IMAGES: \S+/b\.png has the same content as \S+/a\.png \(a copy\): identical "
         r"images have no parallax; give it once$"),
    Case("one image saved twice (no parallax)",
         lambda b, i, o: _ties(b, i, o, "a.png=sw", "b.tif=sw", "c.png=ne"),
         r"IMAGES: a and b show no parallax \(median shift 0\.00 px over \d+ matches\): the "
         r"same view twice \(a copy of an image\?\); remove the copies$"),
    Case("half a JPEG (tiepoints)", lambda b, i, o: (
        _half(b / "images" / "sw.jpg", _in_images(i)), _ties(b, i, o, "ne.jpg=ne"))[1],
         r"sw\.jpg: truncated JPEG: its image data stop at byte \d+ without the end-of-image "
         r"marker \(a copy or a download cut short\?\)$"),
    Case("EO in longitude and latitude (tiepoints)",
         lambda b, i, o: _ties(b, i, o, "sw.png=sw", "ne.png=ne", eo=_eo_lonlat(b, i)),
         r"eo\.csv: the perspective centres \(x 4\.3\d+ to 4\.3\d+, y 52\.\d+ to 52\.\d+\) "
         r"look like longitude and latitude in degrees, 60 units below them the ground: "
         r"footprint pairs need X, Y in a projected CRS, in the unit of Z \(give CRS to check "
         r"it\)$"),
    Case("EO in longitude and latitude, CRS given (tiepoints)", lambda b, i, o: _ties(
        b, i, o, "sw.png=sw", "ne.png=ne", eo=_eo_lonlat(b, i), crs=CRS),
         r"eo\.csv: the perspective centres \(x 4\.3\d+ to 4\.3\d+, y 52\.\d+ to 52\.\d+\) "
         r"looks like longitude and latitude in degrees, not coordinates of 'Amersfoort / RD "
         r"New' \(projected, metre\)$"),
    # -- locatecontrolpoints
    Case("image half the camera's size",
         lambda b, i, o: _locate(b, i, o, "sw.tif=sw@2", "ne.tif=ne"),
         r"sw\.tif: the image is 200 x 150 px, the camera 'k1' 400 x 300 px$"),
    Case("image without an EO row",
         lambda b, i, o: _locate(b, i, o, "sw.tif=sw", "ne.tif=ne", "extra.tif=sw"),
         r"eo\.csv: no exterior orientation for image\(s\) extra \(image_id = file name "
         r"without extension\)$"),
    Case("chip in another CRS than the control",
         lambda b, i, o: _locate(b, i, o, chip_crs="EPSG:3035"),
         r"P1\.tif: the chip is in 'ETRS89-extended / LAEA Europe', the control points in "
         r"'Amersfoort / RD New' \(CRS\): make the chips in the control's CRS$"),
    Case("a cut chip", lambda b, i, o: _locate(b, i, o, cut_chip=True),
         r"P1\.tif: cannot read the pixels: the file is truncated or corrupt \("),
    Case("EO in longitude and latitude (locatecontrolpoints)",
         lambda b, i, o: _locate(b, i, o, eo=_eo_lonlat(b, i)),
         r"eo\.csv: the perspective centres \(x 4\.3\d+ to 4\.3\d+, y 52\.\d+ to 52\.\d+\) "
         r"looks like longitude and latitude in degrees, not coordinates of 'Amersfoort / RD "
         r"New' \(projected, metre\)$"),
]  # fmt: skip


def _refused(argv: list[str], inp: Path, out: Path, capsys, error: str) -> None:
    """Run the command line; assert one error line matching ``error`` (a regex searched in
    it), nothing written, the inputs unchanged."""
    before = _snapshot(inp)
    code = main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2, err
    assert len(err) == 1, err
    assert err[0].startswith(f"lidarphoto {argv[0]}: error: "), err[0]
    assert re.search(error, err[0]), err[0]
    assert _snapshot(out) == {}  # no output, no temporary
    assert _snapshot(inp) == before  # inputs untouched, nothing left beside them


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_bad_input(case, block, tmp_path, capsys):
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    out.mkdir()
    _refused(case.build(block, inp, out), inp, out, capsys, case.error)


def test_orthophotos_larger_than_the_free_space_are_refused(block, tmp_path, capsys,
                                                            monkeypatch):  # fmt: skip
    """The free space of the output folder against the orthophotos' uncompressed size (a
    small disk: 1 MB free), both figures in the message, before anything is written."""
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    out.mkdir()
    argv = _ortho(block, inp, out)
    real = shutil.disk_usage
    monkeypatch.setattr(shutil, "disk_usage", lambda p: real(p)._replace(free=1_000_000))
    _refused(argv, inp, out, capsys,
             r"GSD 0\.06: the 1 orthophoto\(s\) need up to 1\.5 MB \(uncompressed; "
             r"image sw: 581 x 476 cells\); the output folder has 1\.0 MB free: give a "
             r"larger GSD \(0: the images' own\) or free some space$")


_LIMITED = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write beyond the limit fails (EFBIG)
resource.setrlimit(resource.RLIMIT_FSIZE, (int(sys.argv[1]), resource.RLIM_INFINITY))
from lidarphoto.core.cli import main
sys.exit(main(sys.argv[2:]))
"""


def _ortho_fine(b: Path, inp: Path, out: Path) -> list[str]:
    argv = _ortho(b, inp, out)
    argv[argv.index("--gsd") + 1] = "0.03"  # four times as many cells: about 1 MB
    return argv


@pytest.mark.skipif(sys.platform == "win32", reason="no RLIMIT_FSIZE")
@pytest.mark.parametrize(("build", "limit", "written"), [
    (_ortho_fine, 250000, "orthos/sw_ortho.tif"),
    (lambda b, i, o: _mosaic(b, i, o, "sw_ortho.tif", "ne_ortho.tif"), 20000, "m.tif"),
], ids=["orthorectify", "orthomosaic"])  # fmt: skip
def test_a_write_cut_short_names_the_output_and_the_cause(block, tmp_path, build, limit,
                                                          written):  # fmt: skip
    """The orthophoto (about 1 MB) or the mosaic cannot be written whole: the process may
    write files of 250 kB (20 kB) only, as a full disk would cut them (the compiled kernels'
    cache files are smaller). The error names the output file and the cause, and nothing is
    left behind (GDAL's TIFF writer only logs such failures)."""
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    out.mkdir()
    argv = build(block, inp, out)
    before = _snapshot(inp)
    proc = subprocess.run([sys.executable, "-W", "ignore", "-c", _LIMITED, str(limit), *argv],
                          capture_output=True, text=True, timeout=300,
                          env={**__import__("os").environ,
                               "PYTHONDONTWRITEBYTECODE": "1"})  # fmt: skip
    err = [e for e in proc.stderr.strip().splitlines() if not e.startswith("_tiff")]
    assert proc.returncode == 2, proc.stderr
    assert len(err) == 1, err
    assert re.search(rf"^lidarphoto {argv[0]}: error: \S+/out/{written}: cannot write it "
                     rf"whole: the file reached the process's file size limit of {limit} "
                     rf"bytes \(ulimit -f\); nothing was written$", err[0]), err[0]
    assert _snapshot(out) == {}
    assert _snapshot(inp) == before


# ----------------------------------------------------------------------------- bundle
@pytest.fixture(scope="module")
def uav(tmp_path_factory):
    """The simulated UAV block of the bundle tests (15 images, ground points in each)."""
    from lidarphoto.core.simulation.uav_block import simulate_uav_block

    folder = tmp_path_factory.mktemp("uav")
    return simulate_uav_block("bauer", seed=1, n_tie=400).write(folder)


def test_bundle_names_the_eo_row_whose_kappa_is_turned(uav, tmp_path, capsys):
    """Approximate orientations (no sigmas) with one kappa turned by 180 degrees: the
    adjustment meets non-finite values (tie points behind a camera) in another image; the
    error names the EO file, the row and the likely cause."""
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    out.mkdir()
    lines = uav["eo"].read_text(encoding="utf-8").splitlines()
    rows = [line.split(",")[:9] for line in lines]  # the approximate values only
    rows[3][8] = repr(float(rows[3][8]) + 180.0)  # IMG_0103
    eo = inp / "eo.csv"
    eo.write_text("\n".join(",".join(r) for r in rows) + "\n", encoding="utf-8")
    argv = ["bundleadjustment", "--camera", str(_copy(uav["camera"], inp)),
            "--observations", str(_copy(uav["observations"], inp)),
            "--ground-points", str(_copy(uav["ground_points"], inp)), "--eo", str(eo),
            "--crs", "EPSG:31983", "--output-eo", str(out / "eo.csv")]  # fmt: skip
    _refused(argv, inp, out, capsys,
             r"eo\.csv, row 4: the approximate orientation of image IMG_0103 cannot "
             r"be right: its 6 ground points project more than a quarter of the image "
             r"away from their measurements; kappa looks 180 degrees off \(turned by "
             r"\+180 degrees, the ground points fit within \d+ px\) \(the adjustment: "
             r"block '.*' returned non-finite values")


# ----------------------------------------------------------------------------- calibration
@pytest.mark.parametrize("projection", PROJECTIONS)
def test_fisheye_views_name_their_projection(projection):
    """Views of a target simulated through each projection (f = 300 px, lens distortion,
    0.2 px noise; tests/core/test_camera_calibration.py's set): perspective views raise no
    alarm, fisheye ones are recognised with their projection and focal length."""
    from test_camera_calibration import _camera, _views

    fld = target_field(TargetSpec("chessboard", 9, 6, 0.05))
    cam = _camera(projection)
    det = simulate_views(cam, fld, _views(projection), noise_px=0.2, seed=2)
    views = [(fld.xyz[np.isin(fld.ids, d.ids)], d.pixels) for d in det]
    text = fisheye_evidence(views, (cam.width_px, cam.height_px))
    if projection == "perspective":
        assert text == ""
        return
    assert re.fullmatch(
        rf"the views look like a fisheye lens: the target's straight lines fit the "
        rf"{projection} projection \(f 30\d px\) [\d.]+ times better than the perspective one "
        rf"\(RMS misfit .* % of the rays' spread\) and the target is seen up to about \d+ "
        rf"degrees off the axis \(a field of view of about 1[5-9]\d degrees\): try PROJECTION "
        rf"{projection}", text), text  # fmt: skip


@pytest.mark.skipif(not (SHARED / "fisheye-calibration").is_dir(), reason="shared data absent")
def test_fisheye_images_taken_as_perspective_say_so(tmp_path, capsys):
    """BoofCV's 190-degree fisheye chessboard views taken as perspective: the failure
    says the views look like a fisheye lens and which projection to try."""
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    out.mkdir()
    for k in range(1, 26, 3):  # 9 of the 26 views (the run is shorter, the case the same)
        _copy(SHARED / "fisheye-calibration" / "chessboard" / f"{k}.jpg", inp)
    argv = ["calibratecamera", "--images", str(inp), "--target", "chessboard", "--columns",
            "4", "--rows", "6", "--spacing", "1", "--output-camera", str(out / "cam.json")]
    _refused(argv, inp, out, capsys,
             r"camera calibration did not converge in \d+ iterations; the views look "
             r"like a fisheye lens: the target's straight lines fit the (equidistant|"
             r"equisolid|stereographic) projection \(f \d+ px\) .* field of view of about "
             r"[12]\d\d degrees\): try PROJECTION (equidistant|equisolid|"
             r"stereographic)$")


def test_simulated_fisheye_views_taken_as_perspective_say_so(tmp_path, capsys, monkeypatch):
    """The same case in CI, where the BoofCV views are absent: 4 views of a chessboard
    simulated through an equidistant fisheye (f = 300 px; the first of
    tests/core/test_camera_calibration.py's set) are what the target detector finds in 4 image
    files; calibratecamera taken as perspective names the projection to try, writes nothing
    and leaves the images (7 s of CPU: the failing adjustment and its diagnosis)."""
    from lidarphoto.core.photo import calibration_targets
    from test_camera_calibration import _camera, _views

    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    out.mkdir()
    spec = TargetSpec("chessboard", 9, 6, 0.05)
    projection = "equidistant"
    cam = _camera(projection)
    det = simulate_views(cam, target_field(spec), _views(projection)[:4], noise_px=0.2, seed=2)
    blank = np.zeros((cam.height_px, cam.width_px), np.uint8)
    for k in range(len(det)):
        cv2.imwrite(str(inp / f"view{k:02d}.png"), blank)
    by_name = {f"view{k:02d}.png": d for k, d in enumerate(det)}
    monkeypatch.setattr(calibration_targets, "detect_target", lambda img, s, name: by_name[name])
    argv = ["calibratecamera", "--images", str(inp), "--target", "chessboard", "--columns",
            "9", "--rows", "6", "--spacing", "0.05", "--pixel-size", str(cam.pixel_size_mm),
            "--output-camera", str(out / "cam.json")]  # fmt: skip
    _refused(argv, inp, out, capsys,
             rf"camera calibration did not converge in \d+ iterations; the views look like a "
             rf"fisheye lens: the target's straight lines fit the {projection} projection \(f "
             rf"(29[5-9]|30[0-5]) px\) [\d.]+ times better than the perspective one \(RMS "
             rf"misfit .* % of the rays' spread\) and the target is seen up to about \d+ "
             rf"degrees off the axis \(a field of view of about 1[5-9]\d degrees\): try "
             rf"PROJECTION {projection}$")
