"""LiDAR control: intersections against exact geometry, covariance against Monte Carlo,
adjacency, line kinds, and the degenerate cases."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.lidar.control import (
    ControlOptions,
    corner_candidates,
    intersect_three_planes,
    intersect_two_planes,
    lidar_control,
    plane_adjacency,
)

RNG = np.random.default_rng(2024)


def _plane_through(normal, point):
    n = np.asarray(normal, dtype=float)
    n /= np.linalg.norm(n)
    return n, -float(n @ point)


def _random_cov(scale_n: float, scale_d: float) -> np.ndarray:
    a = RNG.normal(size=(4, 4))
    c = a @ a.T / 4.0
    s = np.diag([scale_n, scale_n, scale_n, scale_d])
    return s @ c @ s


@pytest.mark.parametrize("apex", [(10.0, 20.0, 30.0), (485123.4, 7541987.6, 912.3)])
def test_three_planes_exact_and_monte_carlo(apex):
    apex = np.array(apex)
    planes = [_plane_through(n, apex) for n in ((0.5, 0, 0.8), (-0.5, 0.1, 0.8), (0, 0.6, 0.8))]
    n = np.array([p[0] for p in planes])[None]
    d = np.array([p[1] for p in planes])[None]
    cov = np.array([_random_cov(2e-4, 5e-3) for _ in range(3)])[None]
    x, c, cond = intersect_three_planes(n, d, cov)
    np.testing.assert_allclose(x[0], apex, atol=1e-6 * max(1.0, np.abs(apex).max()) * 1e-3)
    assert cond[0] < 10
    # Monte Carlo: sample the plane parameters with their covariance and intersect exactly
    m = 4000
    samples = np.empty((m, 3))
    for i in range(m):
        p = [RNG.multivariate_normal(np.r_[n[0, k], d[0, k]], cov[0, k]) for k in range(3)]
        nn = np.array([q[:3] for q in p])
        dd = np.array([q[3] for q in p])
        samples[i] = np.linalg.solve(nn, -dd)
    resid = samples - x[0]
    maha = np.einsum("mi,ij,mj->m", resid, np.linalg.inv(c[0]), resid)
    # mean of a chi-square with 3 dof is 3, its standard error sqrt(6/m); 5 sigma bound
    assert abs(maha.mean() - 3.0) < 5 * np.sqrt(6.0 / m), maha.mean()


def test_two_planes_line_and_monte_carlo():
    ridge_point = np.array([100.0, 200.0, 15.0])
    n1, d1 = _plane_through((0.0, 0.6, 0.8), ridge_point)
    n2, d2 = _plane_through((0.0, -0.6, 0.8), ridge_point)
    ref = ridge_point + np.array([3.0, 0.4, -0.2])
    c1, c2 = _random_cov(2e-4, 4e-3), _random_cov(2e-4, 4e-3)
    x0, u, cov = intersect_two_planes(
        n1[None], np.array([d1]), c1[None], n2[None], np.array([d2]), c2[None], ref[None]
    )
    np.testing.assert_allclose(np.abs(u[0]), [1.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(x0[0], [103.0, 200.0, 15.0], atol=1e-9)
    m = 4000
    xs, us = np.empty((m, 3)), np.empty((m, 3))
    for i in range(m):
        p1 = RNG.multivariate_normal(np.r_[n1, d1], c1)
        p2 = RNG.multivariate_normal(np.r_[n2, d2], c2)
        raw = np.cross(p1[:3], p2[:3])
        uu = raw / np.linalg.norm(raw)
        a = np.stack([p1[:3], p2[:3], uu])
        xs[i] = np.linalg.solve(a, [-p1[3], -p2[3], uu @ ref])
        us[i] = uu * np.sign(uu @ u[0])
    emp = np.cov(np.hstack([xs, us]).T)
    # compare where the covariance is not degenerate (across the line; u is unit length)
    for block in (slice(0, 3), slice(3, 6)):
        e, p = emp[block, block][1:, 1:], cov[0][block, block][1:, 1:]
        assert np.linalg.norm(e - p) / np.linalg.norm(p) < 0.1


def test_parallel_planes_give_nan():
    n = np.array([[0.0, 0.0, 1.0]])
    x0, _, cov = intersect_two_planes(
        n, np.array([1.0]), np.eye(4)[None], n, np.array([2.0]), np.eye(4)[None], np.zeros((1, 3))
    )
    assert np.all(np.isnan(x0)) and np.all(np.isnan(cov))


# ----------------------------------------------------------------------------- scenes
@dataclass
class P:
    id: int
    normal: np.ndarray
    d: float
    covariance: np.ndarray
    centroid: np.ndarray


def _hip_roof_faces():
    """Exact planes (no noise) of a hip roof (normals tilt away from the ridge): ridge from
    (0,0) to (10,0) at z=14, eaves at z=10 around the rectangle x in [-4, 14], y in [-4, 4]."""
    ridge_a, ridge_b = np.array([0.0, 0.0, 14.0]), np.array([10.0, 0.0, 14.0])
    faces = {
        1: (_plane_through((0, 1, 1), ridge_a), np.array([5.0, 2.0, 12.0])),  # north face
        2: (_plane_through((0, -1, 1), ridge_a), np.array([5.0, -2.0, 12.0])),  # south face
        3: (_plane_through((-1, 0, 1), ridge_a), np.array([-2.0, 0.0, 12.0])),  # west hip end
        4: (_plane_through((1, 0, 1), ridge_b), np.array([12.0, 0.0, 12.0])),  # east hip end
    }
    return faces, ridge_a, ridge_b


def _hip_roof_cloud(spacing: float = 0.25):
    faces, ra, rb = _hip_roof_faces()

    def which(xy):
        # the face a point belongs to is the one with the lowest roof height there (hip roof)
        zs = np.stack(
            [-(f[0][0][0] * xy[:, 0] + f[0][0][1] * xy[:, 1] + f[0][1]) / f[0][0][2]
             for f in faces.values()], 1
        )  # fmt: skip
        return np.argmin(zs, axis=1) + 1

    g = np.arange(-4 + spacing / 2, 14, spacing)
    h = np.arange(-4 + spacing / 2, 4, spacing)
    gx, gy = np.meshgrid(g, h)
    xy = np.column_stack([gx.ravel(), gy.ravel()])
    lab = which(xy)
    pts = np.empty((xy.shape[0], 3))
    for fid, ((n, d), _) in faces.items():
        sel = lab == fid
        pts[sel, :2] = xy[sel]
        pts[sel, 2] = -(n[0] * xy[sel, 0] + n[1] * xy[sel, 1] + d) / n[2]
    planes = [
        P(fid, n, d, np.diag([1e-8, 1e-8, 1e-8, 1e-6]), c) for fid, ((n, d), c) in faces.items()
    ]
    return pts, lab, planes, ra, rb


def test_hip_roof_corners_and_lines():
    pts, lab, planes, ra, rb = _hip_roof_cloud()
    result = lidar_control(planes, pts, lab, ControlOptions(delta=0.4, min_boundary=2.0))
    adj = {tuple(p) for p, a in zip(result.adjacency.pairs.tolist(), result.adjacency.adjacent)
           if a}  # fmt: skip
    assert adj == {(1, 2), (1, 3), (1, 4), (2, 3), (2, 4)}  # 3-4 do not meet
    corners = sorted(tuple(np.round(p.xyz, 6)) for p in result.points)
    assert corners == sorted([tuple(ra), tuple(rb)])
    assert {p.plane_ids for p in result.points} == {(1, 2, 3), (1, 2, 4)}
    # the other chains of adjacent faces meet far from their points: rejected, with the reason
    far = {r.plane_ids for r in result.rejected}
    assert far == {(1, 3, 4), (2, 3, 4)}
    assert all("from the points of plane" in r.reason for r in result.rejected)
    kinds = {line.plane_ids: line.kind for line in result.lines}
    assert kinds[(1, 2)] == "ridge"
    assert all(kinds[k] == "hip" for k in ((1, 3), (1, 4), (2, 3), (2, 4)))
    ridge = next(line for line in result.lines if line.plane_ids == (1, 2))
    ends = sorted([tuple(np.round(ridge.start, 1)), tuple(np.round(ridge.end, 1))])
    assert abs(ridge.length - 10.0) < 0.6  # clipped to the common support (grid spacing)
    assert abs(ends[0][2] - 14.0) < 1e-9 and abs(ends[1][2] - 14.0) < 1e-9


def test_pyramid_apex_from_faces_touching_only_at_the_apex():
    apex = np.array([0.0, 0.0, 20.0])
    normals = [(1, 0, 1), (0, 1, 1), (-1, 0, 1), (0, -1, 1)]
    planes_nd = [_plane_through(n, apex) for n in normals]
    g = np.arange(-8 + 0.125, 8, 0.25)
    gx, gy = np.meshgrid(g, g)
    xy = np.column_stack([gx.ravel(), gy.ravel()])
    zs = np.stack([-(n[0] * xy[:, 0] + n[1] * xy[:, 1] + d) / n[2] for n, d in planes_nd], 1)
    lab = np.argmin(zs, 1) + 1
    pts = np.column_stack([xy, zs.min(1)])
    planes = [P(i + 1, n, d, np.diag([1e-8] * 3 + [1e-6]), np.zeros(3)) for i, (n, d) in
              enumerate(planes_nd)]  # fmt: skip
    result = lidar_control(planes, pts, lab, ControlOptions(delta=0.4, min_boundary=2.0))
    assert len(corner_candidates(result.adjacency)) == 4
    assert len(result.points) == 1  # four triples, one corner
    np.testing.assert_allclose(result.points[0].xyz, apex, atol=1e-9)
    assert sum("same corner" in r.reason for r in result.rejected) == 3


def test_degenerate_cases_are_rejected_with_reasons():
    # three planes sharing one line (a gable plus a third face through the ridge): no point
    ridge = np.array([0.0, 0.0, 10.0])
    nd = [_plane_through(n, ridge) for n in ((0, 1, 1), (0, -1, 1), (0, 0.2, 1))]
    planes = [P(i + 1, n, d, np.diag([1e-8] * 3 + [1e-6]), ridge) for i, (n, d) in enumerate(nd)]
    pts = np.array([[0, 0.1, 10], [0, -0.1, 10], [0.5, 0.0, 10]], float)
    result = lidar_control(
        planes, pts, np.array([1, 2, 3]), ControlOptions(delta=1, min_boundary=0),
        triples=[(1, 2, 3)],
    )  # fmt: skip
    assert not result.points
    assert "line rather than a point" in result.rejected[0].reason
    # nearly parallel planes
    nd = [_plane_through(n, ridge) for n in ((0, 1, 1), (0, -1, 1), (0, 1.05, 1))]
    planes = [P(i + 1, n, d, np.eye(4) * 1e-8, ridge) for i, (n, d) in enumerate(nd)]
    result = lidar_control(planes, pts, np.array([1, 2, 3]), triples=[(1, 2, 3)])
    assert not result.points and "nearly parallel" in result.rejected[0].reason
    # an intersection far from the support of the planes
    nd = [_plane_through(n, ridge) for n in ((0, 1, 1), (0, -1, 1), (1, 0, 1))]
    far_pts = np.array([[50, 0.1, 10], [50, -0.1, 10], [50.5, 0.0, 10]], float)
    planes = [P(i + 1, n, d, np.eye(4) * 1e-8, ridge) for i, (n, d) in enumerate(nd)]
    result = lidar_control(planes, far_pts, np.array([1, 2, 3]), triples=[(1, 2, 3)])
    assert not result.points and "from the points of plane" in result.rejected[0].reason
    # a single plane: nothing, said so
    result = lidar_control(planes[:1], far_pts[:1], np.array([1]))
    assert not result.points and not result.lines and result.rejected


def test_user_triples_are_validated():
    pts, lab, planes, *_ = _hip_roof_cloud()
    with pytest.raises(InputError, match="not found"):
        lidar_control(planes, pts, lab, triples=[(1, 2, 99)])
    with pytest.raises(InputError, match="repeats"):
        lidar_control(planes, pts, lab, pairs=[(1, 1)])
    with pytest.raises(InputError, match="not in the plane table"):
        lidar_control(planes[:2], pts, lab)


def test_adjacency_requires_a_long_enough_boundary():
    pts, lab, *_ = _hip_roof_cloud()
    adj = plane_adjacency(pts, lab, delta=0.4, min_length=50.0)
    assert len(adj.pairs) > 0 and not np.any(adj.adjacent)


def test_tables_round_trip(tmp_path):
    from lidarphoto.core.io.control import (
        read_lcps_csv,
        read_lines_csv,
        write_graph_csv,
        write_lcps_csv,
        write_lines_csv,
    )

    pts, lab, planes, *_ = _hip_roof_cloud()
    for p in planes:  # realistic, full-rank covariances
        object.__setattr__(p, "covariance", _random_cov(1e-4, 1e-2))
    result = lidar_control(planes, pts, lab, ControlOptions(delta=0.4, min_boundary=2.0))
    write_lcps_csv(tmp_path / "lcp.csv", result.points)
    write_lines_csv(tmp_path / "lines.csv", result.lines)
    write_graph_csv(tmp_path / "graph.csv", result.adjacency)
    back = read_lcps_csv(tmp_path / "lcp.csv")
    assert [p.plane_ids for p in back] == [p.plane_ids for p in result.points]
    for a, b in zip(back, result.points):
        np.testing.assert_array_equal(a.xyz, b.xyz)
        np.testing.assert_allclose(a.covariance, b.covariance, rtol=1e-15, atol=0)
    lines = read_lines_csv(tmp_path / "lines.csv")
    assert [(ln.plane_ids, ln.kind) for ln in lines] == [
        (ln.plane_ids, ln.kind) for ln in result.lines
    ]
    for a, b in zip(lines, result.lines):
        np.testing.assert_allclose(a.covariance, b.covariance, rtol=1e-15, atol=0)
        assert a.sigma_ends == pytest.approx(b.sigma_ends, rel=1e-12)
    graph = (tmp_path / "graph.csv").read_text().splitlines()
    assert graph[0].startswith("plane_1,plane_2,adjacent") and len(graph) == 1 + 5  # 3-4 apart
    # a damaged table names the row and the column
    text = (tmp_path / "lines.csv").read_text().splitlines()
    text[2] = text[2].replace(",hip,", ",gutter,", 1)
    (tmp_path / "bad.csv").write_text("\n".join(text))
    with pytest.raises(InputError, match=r"row 3.*'kind'.*gutter"):
        read_lines_csv(tmp_path / "bad.csv")
