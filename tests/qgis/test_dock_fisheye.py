"""A fisheye camera in the picking dock, in real QGIS (QTest clicks on the view).

Data: the simulated town of test_image_dock flown with an equisolid fisheye (f 3 mm, 2000 x
1500 px of 3 um, Brown k1; 77 degrees off the axis in the corners) at 150 m, noise-free, the
EO of the true trajectory and mount, 16-bit frames with the roofs painted where the camera
model puts them. Besides the roof ridges (10-20 m, nearly straight in the image) the line
layer holds long 3-D lines between the control points (100-400 m) whose images are clearly
curved. Truth: those lines' points projected one by one (core.photo.picking.PickingScene's
chain, 2,001 points a line), against which the drawn overlay paths are checked.
"""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.distortion import distortion_from_dict
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.io.orientation import write_eo_csv
from lidarphoto.core.photo.georeference import direct_georeference
from lidarphoto.core.photo.mount import Mount
from lidarphoto.core.photo.picking import CHORD_TOL_PX, PickingScene
from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight
from osgeo import gdal
from qgis.core import QgsGeometry, QgsLineString, QgsPoint, QgsProject
from qgis.PyQt.QtCore import QPointF, Qt
from qgis.PyQt.QtTest import QTest
from qgis.PyQt.QtWidgets import QGraphicsPathItem
from test_image_dock import CRS, _add, _dock, _memory_layer, _polygon, _screen_pixel

LENS = distortion_from_dict({"model": "brown_conrady", "k1": 1e-3})
FISHEYE = Camera("fisheye frame", 3.0, 0.003, 2000, 1500, 0.0, 0.0, LENS, "equisolid")
CONFIG = FlightConfig(
    camera=FISHEYE,
    flying_height_m=150.0,
    n_buildings=9,
    n_planes=24,
    town_size_m=400.0,
    n_check=0,
    types=("tie", "line", "lcp"),
    ties_per_plane=2,
    plane_source="exact",
)


@pytest.fixture(scope="module")
def fisheye_block(tmp_path_factory):
    """The fisheye project on disk: camera JSON (equisolid), EO, tables, frames; the roof
    outlines and the lines of the line layer (ridges, then the long lines)."""
    import cv2

    out = tmp_path_factory.mktemp("fisheye")
    sim = simulate_flight(CONFIG, seed=5, exact=True)
    paths = sim.write(out)
    group = sim.truth.groups[0]
    mount = Mount(sim.truth.lever_arm, sim.mount.nominal, sim.truth.boresight[group])
    eo = direct_georeference(sim.truth.trajectory, mount, MappingFrame.from_user_input(CRS))
    write_eo_csv(out / "eo.csv", eo)
    faces = {f.face_id: f for f in sim.town.faces}
    outlines = [faces[int(p.id)].polygon for p in sim.planes]
    scene = PickingScene(eo, FISHEYE, CRS)
    rng = np.random.default_rng(0)
    images = []
    for image_id in eo.image_id:
        img = rng.normal(1000, 25, (FISHEYE.height_px, FISHEYE.width_px)).astype(np.uint16)
        for k, ring in enumerate(scene.project_rings(image_id, outlines)):
            if np.isfinite(ring).all():
                cv2.fillPoly(img, [np.round(ring * 16).astype(np.int32)],
                             700 + 150 * (k % 5), shift=4)  # fmt: skip
        path = out / f"{image_id}.tif"
        ds = gdal.GetDriverByName("GTiff").Create(
            str(path), FISHEYE.width_px, FISHEYE.height_px, 1, gdal.GDT_UInt16, ["TILED=YES"]
        )
        ds.GetRasterBand(1).WriteArray(img)
        ds = None
        images.append(path)
    lcp = np.array([c.xyz for c in sim.lcps])
    pairs = [(i, j) for i in range(len(lcp)) for j in range(i + 1, len(lcp))
             if np.hypot(*(lcp[i, :2] - lcp[j, :2])) > 100.0]  # fmt: skip
    lines = [(str(ln.id), np.asarray(ln.start), np.asarray(ln.end)) for ln in sim.lines]
    long_ids = [str(900 + k) for k in range(len(pairs))]
    lines += [(lid, lcp[i], lcp[j]) for lid, (i, j) in zip(long_ids, pairs)]
    return {"sim": sim, "paths": paths, "eo": out / "eo.csv", "images": images,
            "outlines": outlines, "scene": scene, "lines": lines, "long": long_ids}  # fmt: skip


@pytest.fixture()
def fisheye_layers(fisheye_block, qgis_new_project):
    b, sim = fisheye_block, fisheye_block["sim"]
    planes = _memory_layer("PolygonZ", CRS, "roof planes")
    _add(planes, [_polygon(r) for r in b["outlines"]], [p.id for p in sim.planes])
    lines = _memory_layer("LineStringZ", CRS, "lines")
    geoms = [QgsGeometry(QgsLineString([QgsPoint(*map(float, a)), QgsPoint(*map(float, e))]))
             for _lid, a, e in b["lines"]]  # fmt: skip
    _add(lines, geoms, [int(lid) for lid, _a, _e in b["lines"]])
    lcps = _memory_layer("PointZ", CRS, "lcps")
    _add(lcps, [QgsGeometry(QgsPoint(*map(float, c.xyz))) for c in sim.lcps],
         [c.id for c in sim.lcps])  # fmt: skip
    QgsProject.instance().addMapLayers([planes, lines, lcps])
    return planes, lines, lcps


def _drawn_paths(dock) -> list[np.ndarray]:
    """The vertices (K, 2) of every line path the overlays drew (their QPainterPaths)."""
    out = []
    for item in dock.viewer.overlays.groups["lines"].childItems():
        if isinstance(item, QGraphicsPathItem):
            path = item.path()
            out.append(np.array([[path.elementAt(i).x, path.elementAt(i).y]
                                 for i in range(path.elementCount())]))  # fmt: skip
    return out


def _distance(points: np.ndarray, curve: np.ndarray) -> np.ndarray:
    """Distance of points (P, 2) to a densely sampled curve (M, 2) taken as a polyline."""
    a, b = curve[:-1], curve[1:]
    ab = b - a
    len2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    t = np.clip(np.einsum("pij,ij->pi", points[:, None] - a[None], ab) / len2, 0, 1)
    near = a[None] + t[..., None] * ab[None]
    return np.hypot(*(near - points[:, None]).transpose(2, 0, 1)).min(axis=1)


def test_fisheye_camera_in_the_dock(qgis_parent, qgis_app, fisheye_block, fisheye_layers,
                                    tmp_path):  # fmt: skip
    """The equisolid camera loads (no refusal); its lines are drawn as curves: the long
    lines with many vertices, every drawn vertex within CHORD_TOL_PX of the exact image and
    every exact point in the frame within CHORD_TOL_PX of the drawn path; a real click on a
    roof adds a tie observation at the clicked pixel with its prediction in the other
    images; a click in line mode on a curve starts an image line of that LiDAR line."""
    b = fisheye_block
    dock = _dock(qgis_parent, qgis_app, b, fisheye_layers, tmp_path)
    assert dock.camera is not None and dock.camera.projection == "equisolid"
    assert not any("not loaded" in m for m in dock.messages), dock.messages
    scene, cam = b["scene"], FISHEYE
    image = b["sim"].trajectory.image_id[1]
    dock.show_image(image)
    overlays = dock.viewer.overlays
    proj = dock.picking.projected
    assert proj is not None and proj.image_id == image
    assert overlays.counts["planes"] >= 5 and overlays.counts["lines"] >= 10
    ids = [lid for lid, _a, _e in b["lines"]]
    by_id = dict(zip(ids, proj.lines))
    long_seen = [lid for lid in b["long"] if np.isfinite(by_id[lid]).all()
                 and cam.in_frame(by_id[lid], 0.0).all()]  # fmt: skip
    assert len(long_seen) >= 3, long_seen
    assert max(len(by_id[lid]) for lid in long_seen) >= 10
    drawn = _drawn_paths(dock)
    assert len(drawn) == overlays.counts["lines"]
    assert overlays.line_vertices == sum(len(p) for p in drawn) > 3 * len(drawn)
    # every drawn path on the exact image of its line (the paths are drawn in line order,
    # lines without two finite vertices left out): match each path to its line by vertices
    lines = {lid: (a, e) for lid, a, e in b["lines"]}
    t = np.linspace(0.0, 1.0, 2001)
    checked, worst, bows = 0, 0.0, []
    for lid in long_seen:
        a, e = lines[lid]
        exact = scene.project(image, a[None] + t[:, None] * (e - a)[None])
        path = next(p for p in drawn if len(p) == len(by_id[lid])
                    and np.allclose(p, by_id[lid]))  # fmt: skip
        assert _distance(path, exact).max() <= CHORD_TOL_PX
        inside = exact[cam.in_frame(exact, 0.0)]
        assert _distance(inside, path).max() <= CHORD_TOL_PX
        # and the curve is not the chord: the straight segment between the ends is off it
        bow = float(_distance(exact, path[[0, -1]]).max())
        assert bow > 2.0
        worst = max(worst, float(_distance(path, exact).max()),
                    float(_distance(inside, path).max()))  # fmt: skip
        checked += 1
        bows.append(bow)
    assert checked >= 3
    print(
        f"\n{checked} long lines in {image}: vertices {[len(by_id[i]) for i in long_seen]}, "
        f"off their chords up to {max(bows):.1f} px, drawn within {worst:.3f} px of the "
        f"exact image; {overlays.line_vertices} vertices for {len(drawn)} lines drawn"
    )

    # a real click on a roof (zoom 2, the centre of an outline wholly inside the image)
    k, centre = next((k, r.mean(axis=0))
                     for k, r in enumerate(proj.rings)
                     if np.isfinite(r).all() and cam.in_frame(r, 200).all())  # fmt: skip
    target = str(b["sim"].planes[k].id)
    view = dock.view
    dock.viewer.type_combo.setCurrentText("tie")
    view.set_zoom(2.0, QPointF(*centre))
    qgis_app.processEvents()
    click = _screen_pixel(view, centre)
    QTest.mouseClick(view.viewport(), Qt.MouseButton.LeftButton,
                     Qt.KeyboardModifier.NoModifier, click)  # fmt: skip
    assert len(dock.store.rows) == 1, dock.messages[-3:]
    o = dock.store.rows[0]
    assert (o.image_id, o.type, o.target_id) == (image, "tie", target)
    assert max(abs(o.col - centre[0]), abs(o.row - centre[1])) <= 0.25
    pending = dock.session.pending
    assert pending is not None and len(pending.pixels) >= 1
    control = dock.session.control
    plane = control.planes[control.plane_ids.index(target)]
    ground, _ = scene.ray_plane(image, (o.col, o.row), [plane.normal], [plane.centroid])
    for other, px in pending.pixels.items():  # the prediction: that roof point seen there
        np.testing.assert_allclose(px, scene.project(other, ground)[0], atol=1e-6)
    dock.session.cancel_prediction()

    # line mode: a click on the curve starts an image line of that LiDAR line (points on
    # its curved image; tests/qgis/test_dock_fisheye_lines.py), nothing added yet
    lid = long_seen[0]
    on_line = by_id[lid][len(by_id[lid]) // 2]
    dock.viewer.type_combo.setCurrentText("line")
    assert dock.pick(float(on_line[0]), float(on_line[1])) == -1
    half = dock.session.half_line
    assert half is not None and half.target.target_id == lid, dock.messages[-1]
    assert len(dock.store.rows) == 1
    assert dock.picking.cancel_line() and dock.session.half_line is None
    # the hit test follows the curve: the line under the curve's middle vertex is found
    targets = dock.session.targets_at(image, on_line, "line", 0.5, proj)
    assert targets and targets[0].target_id == lid
    dock.close()


def test_fisheye_resection_from_the_dock_leaves_the_lines_out(
    qgis_parent, qgis_app, fisheye_block, fisheye_layers, tmp_path
):
    """An observation file with line rows of the image (the simulation's, exact), then the
    control points clicked in the dock (real clicks at 100 %: the centres of the pixels
    holding their projections, at most 0.5 px off) and Resect: the dock says the line rows
    are left out (fisheye), and the job recovers the true pose from the points within 4 of
    its reported sigmas."""
    from lidarphoto.core.io.observations import write_observations_csv
    from lidarphoto.core.io.orientation import read_eo_csv
    from test_dock_lines import _click
    from test_image_dock import _wait

    b = fisheye_block
    sim = b["sim"]
    image = sim.trajectory.image_id[4]
    obs = sim.observations
    lines_here = obs.mask("line") & (np.asarray(obs.image_id) == image)
    assert lines_here.sum() >= 4
    write_observations_csv(tmp_path / "lines.csv", obs.subset(lines_here))
    dock = _dock(qgis_parent, qgis_app, b, fisheye_layers, tmp_path, obs_name="lines.csv")
    assert len(dock.store.rows) == int(lines_here.sum())
    dock.show_image(image)
    dock.viewer.type_combo.setCurrentText("lcp")
    lcp_px = b["scene"].project(image, np.array([c.xyz for c in sim.lcps]))
    seen = [k for k, p in enumerate(lcp_px)
            if np.isfinite(p).all() and FISHEYE.in_frame(p[None], 40.0)[0]]  # fmt: skip
    assert len(seen) >= 4, seen
    for k in seen:
        _click(dock, lcp_px[k])
    assert sum(o.type == "lcp" for o in dock.store.rows) == len(seen), dock.messages[-3:]
    finished = []
    dock.resectionFinished.connect(finished.append)
    assert dock.run_resection()
    assert any("left out" in m and "fisheye" in m for m in dock.messages), dock.messages[-3:]
    assert _wait(qgis_app, lambda: bool(finished), 120.0)
    assert finished == [True], dock.resection.error
    run = dock.resection.run
    assert run.image_id == image and run.image.data.n_lines == 0
    truth = read_eo_csv(b["eo"])
    k = list(truth.image_id).index(image)
    std = run.result.std
    dxyz = run.result.xyz - truth.xyz[k]
    dopk = (run.result.opk - truth.opk[k] + np.pi) % (2 * np.pi) - np.pi
    assert np.all(np.abs(dxyz) < 4 * std[:3]), (dxyz, std[:3])
    assert np.all(np.abs(dopk) < 4 * std[3:]), (dopk, std[3:])
    print(
        f"\nfisheye resection of {image} from {len(seen)} LCPs: dxyz {np.round(dxyz, 3)} m "
        f"(sigma {np.round(std[:3], 3)}), dopk {np.round(np.degrees(dopk), 4)} deg "
        f"(sigma {np.round(np.degrees(std[3:]), 4)})"
    )
    dock.close()
