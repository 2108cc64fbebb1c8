"""The picking dock's projection of lines and outlines through fisheye cameras
(core.photo.picking.PickingScene.project_segments, project_rings; the session's
ProjectedControl), against the exact projection of points along each 3-D segment.

Scene: a fisheye of each projection (f 2 mm, 2000 x 1500 px of 3 um, Brown k1 k2, principal
point off the centre) 40 m over the ground, tilted 20 degrees, and 300 random segments 5-150 m
long around it (some pass beyond 90 degrees off the axis, and so beyond the orthographic
field; some leave the frame). Truth: 4,001 points along each segment (straight in the local
frame the scene computes in) projected one by one with the same forward model
(core.geometry.collinearity.project); every one of them inside the frame must lie within
CHORD_TOL_PX (0.25 px) of the drawn polyline. A perspective camera keeps the end points only.
"""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.geometry.distortion import distortion_from_dict
from lidarphoto.core.photo.control_features import ControlFeature, ControlSet
from lidarphoto.core.photo.orientation import ExteriorOrientationTable
from lidarphoto.core.photo.picking import CHORD_TOL_PX, PickingScene, points_in_polygons
from lidarphoto.core.photo.picking_session import PickingSession

CRS = "EPSG:28992"
FISHEYES = ("equidistant", "equisolid", "orthographic", "stereographic")
CENTRE = np.array([85000.0, 446000.0, 40.0])


def _camera(projection: str) -> Camera:
    lens = distortion_from_dict({"model": "brown_conrady", "k1": 2e-3, "k2": -1e-4})
    return Camera("fish", 2.0, 0.003, 2000, 1500, 0.03, -0.02, lens, projection)


def _scene(projection: str) -> PickingScene:
    eo = ExteriorOrientationTable(("img1",), np.array([np.nan]), ("",), CENTRE[None],
                                  np.radians([[20.0, -8.0, 30.0]]), CRS)  # fmt: skip
    return PickingScene(eo, _camera(projection))


def _segments(n: int = 300, seed: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Segments (mapping CRS) on and above the ground around the camera's nadir."""
    rng = np.random.default_rng(seed)
    mid = CENTRE + np.column_stack([rng.uniform(-90, 90, (n, 2)), rng.uniform(-40, -25, n)])
    d = rng.normal(size=(n, 3)) * [1.0, 1.0, 0.2]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    half = rng.uniform(2.5, 75.0, n)[:, None]
    return mid - half * d, mid + half * d


def _distance_to_polyline(points: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Distance (px) of each point (P, 2) to the nearest finite edge of a polyline (K, 2)."""
    a, b = poly[:-1], poly[1:]
    ok = np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1)
    a, b = a[ok], b[ok]
    if len(a) == 0:
        return np.full(len(points), np.inf)
    ab = b - a
    len2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    t = np.clip(np.einsum("pij,ij->pi", points[:, None] - a[None], ab) / len2, 0, 1)
    near = a[None] + t[..., None] * ab[None]
    return np.hypot(*(near - points[:, None]).transpose(2, 0, 1)).min(axis=1)


def _truth(scene: PickingScene, a: np.ndarray, b: np.ndarray, m: int = 4001) -> np.ndarray:
    """(L, m, 2) exact pixels of m points along each segment (NaN outside the field)."""
    la, lb = scene.to_local(a), scene.to_local(b)
    t = np.linspace(0.0, 1.0, m)
    pts = la[:, None] + t[None, :, None] * (lb - la)[:, None]
    return project(pts.reshape(-1, 3), scene.local_eo[0], scene.camera).reshape(len(a), m, 2)


@pytest.mark.parametrize("projection", FISHEYES)
def test_fisheye_lines_within_the_tolerance_of_their_exact_image(projection):
    scene = _scene(projection)
    a, b = _segments()
    polys = scene.project_segments("img1", a, b)
    truth = _truth(scene, a, b)
    cam = scene.camera
    worst, back, counted, vertices = 0.0, 0.0, 0, []
    for poly, exact in zip(polys, truth):
        assert poly.ndim == 2 and poly.shape[1] == 2 and len(poly) >= 2
        seen = np.isfinite(exact).all(axis=1) & cam.in_frame(exact, 0.0)
        if not seen.any():
            continue
        d = _distance_to_polyline(exact[seen], poly)
        worst, counted = max(worst, float(d.max())), counted + int(seen.sum())
        vertices.append(int(np.isfinite(poly).all(axis=1).sum()))
        # and the other way: the drawn vertices and edge midpoints lie on the exact curve
        fin = np.vstack([poly, 0.5 * (poly[1:] + poly[:-1])])
        fin = fin[np.isfinite(fin).all(axis=1) & cam.in_frame(fin, 0.0)]
        if len(fin):
            back = max(back, float(_distance_to_polyline(fin, exact).max()))
    assert counted > 100_000 and len(vertices) > 150
    assert worst <= CHORD_TOL_PX and back <= CHORD_TOL_PX, (projection, worst, back)
    # lines through a fisheye are curves: many more vertices than the two ends
    assert np.median(vertices) > 4, vertices
    print(
        f"\n{projection}: worst {worst:.3f} px (back {back:.3f}) over {counted} points, "
        f"vertices median {np.median(vertices):.0f}, max {max(vertices)} "
        f"({len(vertices)} lines seen)"
    )


def test_orthographic_line_beyond_its_field_is_cut_at_the_field_edge():
    """A segment from below the camera to far behind it (beyond 90 degrees off the axis):
    the polyline keeps the visible run only, ending at the image circle r = f (within the
    tolerance), a NaN-free run; a segment wholly behind gives two NaN rows."""
    scene = _scene("orthographic")
    cam = scene.camera
    local = scene.local_eo[0]
    from lidarphoto.core.geometry.rotations import opk_to_matrix

    r = opk_to_matrix(*local[3:])  # camera -> local: columns are the camera axes
    axis = -r[:, 2]  # the viewing direction in the local frame
    side = r[:, 0]
    c = local[:3]
    a_loc = c + 30.0 * axis + 5.0 * side  # in front
    b_loc = c - 30.0 * axis + 60.0 * side  # behind
    to_map = scene.local.enu_to_map
    poly = scene.project_segments("img1", to_map(a_loc[None]), to_map(b_loc[None]))[0]
    assert np.isfinite(poly).all() and len(poly) > 4
    # the last vertex lies on the field's edge: ideal radius f (ideal = measured + d), and
    # next to the last visible one of 20,001 exact points along the segment
    r_mm = np.hypot(*cam.ideal_from_pixel(poly[-1:])[0])
    assert abs(r_mm / cam.focal_mm - 1.0) < 1e-6, r_mm
    truth = _truth(scene, to_map(a_loc[None]), to_map(b_loc[None]), 20001)[0]
    fin = truth[np.isfinite(truth).all(axis=1)]
    assert len(fin) < len(truth) and np.hypot(*(poly[-1] - fin[-1])) < 1.0
    behind = scene.project_segments("img1", to_map((c - 30 * axis)[None]),
                                    to_map((c - 40 * axis + side)[None]))[0]  # fmt: skip
    assert behind.shape == (2, 2) and np.isnan(behind).all()


@pytest.mark.parametrize("projection", ("equisolid", "stereographic"))
def test_fisheye_rings_densified_and_picked(projection):
    """A square roof outline 20 m across seen 40-60 degrees off the axis: its projected ring
    has many vertices, each edge within the tolerance of its exact image, and a pixel inside
    the exact outline near the middle of an edge (where the straight chord between the
    corners would cut it off) is inside the ring."""
    scene = _scene(projection)
    cen = CENTRE + [45.0, -30.0, -35.0]
    ring = cen + np.array([[-10, -10, 0], [10, -10, 0], [10, 10, 0], [-10, 10, 0]], float)
    px = scene.project_rings("img1", [ring])[0]
    assert np.isfinite(px).all() and len(px) > 12
    exact = _truth(scene, ring, np.roll(ring, -1, axis=0))
    d = _distance_to_polyline(exact.reshape(-1, 2), np.vstack([px, px[:1]]))
    assert d.max() <= CHORD_TOL_PX
    corners = scene.project("img1", ring)
    assert points_in_polygons(corners.mean(axis=0), [px]).tolist() == [0]
    # the perspective camera's ring: its projected corners, unchanged
    persp = PickingScene(scene.eo, Camera("p", 2.0, 0.003, 2000, 1500))
    np.testing.assert_array_equal(persp.project_rings("img1", [ring])[0],
                                  persp.project("img1", ring))  # fmt: skip


def test_perspective_lines_stay_two_points():
    scene = PickingScene(_scene("equidistant").eo, Camera("p", 8.0, 0.003, 2000, 1500))
    a, b = _segments(50)
    polys = scene.project_segments("img1", a, b)
    assert len(polys) == 50 and all(p.shape == (2, 2) for p in polys)
    np.testing.assert_array_equal(np.array(polys)[:, 0], scene.project("img1", a))
    np.testing.assert_array_equal(np.array(polys)[:, 1], scene.project("img1", b))
    assert scene.project_segments("img1", np.empty((0, 3)), np.empty((0, 3))) == []


def _line_session(projection: str) -> tuple[PickingSession, np.ndarray, np.ndarray]:
    scene = _scene(projection)
    session = PickingSession()
    session.set_orientation(scene.camera, scene.eo, CRS)
    a, b = _segments(40, seed=9)
    feats = [ControlFeature(str(k), np.vstack([a[k], b[k]])) for k in range(len(a))]
    session.control = ControlSet.from_features(lines=feats)
    return session, a, b


@pytest.mark.parametrize("projection", FISHEYES)
def test_session_measures_points_on_the_curved_line(projection):
    """The dock's session with a fisheye camera: the lines come as polylines, a click on the
    exact image of a line's 3-D midpoint hits that line (0.5 px tolerance); an image line is
    started there (no refusal), holds the line's curve, and gives the curve's direction at a
    click (what the dock refines across) within 0.5 degrees of the exact image's tangent
    (central differences of the projection, 1e-4 of the segment); the second click on the
    curve gives two line rows on the LiDAR line. A perspective camera's lines are straight."""
    session, a, b = _line_session(projection)
    assert session.lines_curved()
    proj = session.project("img1")
    assert len(proj.lines) == len(a)
    assert np.nanmax([len(p) for p in proj.lines]) > 4
    cam, scene = session.camera, session.scene
    hit, worst, curved, most = 0, 0.0, 0, 0.0
    for k in range(len(a)):
        t = np.array([0.3, 0.5, 0.5 - 1e-4, 0.5 + 1e-4, 0.7])
        exact = scene.project("img1", a[k] + t[:, None] * (b[k] - a[k]))
        m = exact[1]
        if not (np.isfinite(exact).all() and cam.in_frame(exact, 5.0).all()):
            continue
        target = session.targets_at("img1", m, "line", 0.5, proj)
        assert target and target[0].target_id == str(k), (k, target)
        hit += 1
        half = session.start_line("img1", m, target[0], proj)
        assert half.curve is not None and np.array_equal(half.curve, proj.lines[k])
        tangent = exact[3] - exact[2]
        tangent /= np.hypot(*tangent)
        got = half.direction_at(m)
        assert abs(np.hypot(*got) - 1.0) < 1e-12
        angle = np.degrees(np.arccos(min(1.0, abs(float(got @ tangent)))))
        worst = max(worst, angle)
        assert angle < 0.5, (k, angle)
        # the chord of the projected end points (the perspective direction) is off the curve
        ends = scene.project("img1", np.vstack([a[k], b[k]]))
        chord = ends[1] - ends[0]
        bend = np.degrees(np.arccos(min(1.0, abs(chord @ tangent) / np.hypot(*chord))))
        curved += bend > 10 * max(angle, 0.05)
        most = max(most, bend)
        row = session.finish_line("img1", exact[4])
        assert row >= 0
        r0, r1 = session.observations.rows[row : row + 2]
        assert (r0.type, r0.target_id, r1.target_id) == ("line", str(k), str(k))
        assert (r0.col, r0.row, r1.col, r1.row) == (*m, *exact[4])
    assert hit >= 10 and curved >= 3, (hit, curved)
    print(f"\n{projection}: {hit} lines, tangent within {worst:.3f} deg, the end points' "
          f"chord up to {most:.1f} deg off it")  # fmt: skip
    persp = PickingSession()
    persp.set_orientation(Camera("p", 8.0, 0.003, 2000, 1500), session.eo, CRS)
    assert not persp.lines_curved()


@pytest.mark.parametrize("projection", ("equidistant", "equisolid", "stereographic"))
def test_segment_past_the_backward_axis(projection):
    """A segment passing just behind the camera, next to its backward axis (theta near 180
    deg, inside the field of these projections): its image swings around the image circle
    (in part inside the frame for the equisolid). In the frame, the exact image within the
    tolerance of the polyline and the polyline's vertices and edge midpoints within the
    tolerance of the exact image (no chord across the image)."""
    from lidarphoto.core.geometry.rotations import opk_to_matrix

    scene = _scene(projection)
    cam = scene.camera
    local = scene.local_eo[0]
    r = opk_to_matrix(*local[3:])
    axis, side, c = -r[:, 2], r[:, 0], local[:3]
    to_map = scene.local.enu_to_map
    a, b = to_map((c - 30 * axis - 40 * side)[None]), to_map((c - 30 * axis + 40 * side)[None])
    poly = scene.project_segments("img1", a, b)[0]
    exact = _truth(scene, a, b, 20001)[0]
    seen = exact[np.isfinite(exact).all(axis=1) & cam.in_frame(exact, 0.0)]
    if len(seen):
        assert _distance_to_polyline(seen, poly).max() <= CHORD_TOL_PX
    fin = np.vstack([poly, 0.5 * (poly[1:] + poly[:-1])])
    fin = fin[np.isfinite(fin).all(axis=1) & cam.in_frame(fin, 0.0)]
    if len(fin):
        assert _distance_to_polyline(fin, exact).max() <= CHORD_TOL_PX
    assert len(seen) > 0 or len(fin) == 0
    if projection == "equisolid":
        assert len(seen) > 100  # the case is not vacuous


def test_a_jump_of_the_image_is_a_gap_not_a_chord():
    """Where the image of a segment jumps (a line exactly through the backward axis or the
    centre: points on either side map to opposite sides of the image), the piece across the
    jump stays bent after every halving and is left out: a NaN gap, not a chord."""
    from lidarphoto.core.photo.picking import _densify

    def jumping(p):  # x in [0, 1] -> a straight image with a 500 px jump at x = 0.6
        x = p[:, 0]
        return np.column_stack([100.0 * x + np.where(x < 0.6, 0.0, 500.0), 50.0 + 0 * x])

    a, b = np.array([[0.0, 0.0, -1.0]]), np.array([[1.0, 0.0, -1.0]])
    poly = _densify(jumping, np.zeros(3), a, b, (1000.0, 100.0), CHORD_TOL_PX)[0]
    gap = np.flatnonzero(np.isnan(poly[:, 0]))
    assert gap.size == 1
    before, after = poly[: gap[0]], poly[gap[0] + 1 :]
    assert before[0, 0] == 0.0 and after[-1, 0] == 600.0
    assert abs(before[-1, 0] - 60.0) < 1e-6 and abs(after[0, 0] - 560.0) < 1e-6
