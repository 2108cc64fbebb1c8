"""The roof-plane extraction compiled with numba (core/lidar/roof_planes_numba.py) against its
numpy fallback (scipy's cKDTree and vectorised numpy): the same neighbours, RANSAC decisions,
local normals, regions and planes, bit for bit, on noisy and on quantised clouds (ties at the
k-th distance) and on the real AHN3 crop.

Each back end is checked against truth on its own in test_roof_planes.py (the default, numba,
there); the Jacobi normals against LAPACK here."""

from __future__ import annotations

import os
from pathlib import Path

import laspy
import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.lidar import roof_planes_numba as compiled
from lidarphoto.core.lidar.roof_planes import (
    RoofPlaneParams,
    _jacobi_normals,
    _local_planes,
    _spatial_order,
    extract_roof_planes,
)
from lidarphoto.core.lidar.roof_planes_local import _eig_normals
from lidarphoto.core.simulation.town import CLASS_GROUND, simulate_town

AHN3 = Path(__file__).resolve().parents[1] / "data" / "ahn3" / "ahn3_delft_crop60.laz"

if not compiled.AVAILABLE:
    if os.environ.get("LIDARPHOTO_REQUIRE_NUMBA") == "1":  # set by scripts/test.sh
        raise RuntimeError("numba is required by the test environment but does not import")
    pytest.skip("numba is not installed", allow_module_level=True)


def _both_local(xyz, params):
    origin = np.floor(xyz.min(axis=0))
    out = {}
    for backend in ("numba", "numpy"):
        order, grid = _spatial_order(xyz, origin, params.k_neighbours, backend == "numba")
        out[backend] = (order, *_local_planes(grid, params, backend, None, None))
    return out


def _assert_same_local(out):
    a, b = out["numba"], out["numpy"]
    np.testing.assert_array_equal(a[0], b[0])  # the order (counting sort = stable argsort)
    for x, y, name in zip(a[1:5], b[1:5], ("keep", "normals", "quality", "knn")):
        np.testing.assert_array_equal(x, y, err_msg=name)
    np.testing.assert_array_equal(a[5], b[5])  # the distances to the 4th neighbour


def test_neighbours_and_ransac_agree_on_a_noisy_cloud():
    _, pts = simulate_town(n_buildings=4, n_trees=3, density=8.0, seed=5)
    xyz = pts.xyz[pts.classification != CLASS_GROUND] + [85000.0, 447000.0, 0.0]
    out = _both_local(xyz, RoofPlaneParams(batch_size=1000))
    _assert_same_local(out)
    keep = out["numba"][1]
    assert 0.3 < keep.mean() < 0.95  # both outcomes occur


def test_ties_at_the_kth_distance_go_to_the_lower_index():
    """Integer coordinates on a lattice: many neighbours at exactly the same distance. The K
    nearest are those with the smallest (distance, index), in both back ends."""
    rng = np.random.default_rng(2)
    g = np.stack(np.meshgrid(np.arange(40), np.arange(30), np.arange(2)), -1).reshape(-1, 3)
    xyz = g[rng.permutation(len(g))].astype(np.float64) * [1.0, 1.0, 0.5]
    params = RoofPlaneParams(k_neighbours=12, min_support=10, batch_size=500)
    out = _both_local(xyz, params)
    _assert_same_local(out)
    order, knn = out["numba"][0], out["numba"][4]
    q = xyz[order]
    # brute force on the sorted points for a few rows: (d2, index) order
    for i in (0, 17, 1000, len(q) - 1):
        d2 = ((q - q[i]) ** 2).sum(axis=1)
        best = np.lexsort((np.arange(len(q)), d2))[: knn.shape[1]]
        np.testing.assert_array_equal(knn[i], best)


def test_points_beyond_the_cells_reach_search_every_point():
    """Isolated points with fewer than K others within the search's 64 cells (the compiled
    search's pass over every point): the same K nearest as the numpy back end and as brute
    force, ties included (integer coordinates)."""
    rng = np.random.default_rng(6)
    g = np.stack(np.meshgrid(np.arange(60), np.arange(50), np.arange(2)), -1).reshape(-1, 3)
    far = np.array([[10000, 10000, 0], [10001, 10000, 1], [-10000, 10000, 3], [0, 10000, 2]])
    xyz = np.vstack([g, far])[rng.permutation(len(g) + len(far))].astype(np.float64)
    params = RoofPlaneParams(k_neighbours=12, min_support=10, batch_size=500)
    cell = _spatial_order(xyz, np.floor(xyz.min(axis=0)), params.k_neighbours, True)[1].cell
    out = _both_local(xyz, params)
    _assert_same_local(out)
    order, knn = out["numba"][0], out["numba"][4]
    q = xyz[order]
    far_rows = np.flatnonzero(q[:, 1] > 1000)
    assert len(far_rows) == 4
    for i in far_rows:
        d2 = ((q - q[i]) ** 2).sum(axis=1)
        best = np.lexsort((np.arange(len(q)), d2))[: knn.shape[1]]
        np.testing.assert_array_equal(knn[i], best)
        # the K-th neighbour lies beyond the 64 cells around the point: found by that pass
        assert np.sqrt(d2[best[-1]]) > 65 * np.sqrt(2.0) * cell


@pytest.mark.parametrize("source", ["town", "ahn3"])
def test_the_same_planes_both_ways(source):
    if source == "town":
        _, pts = simulate_town(n_buildings=6, n_trees=4, density=8.0, seed=8)
        xyz = pts.xyz[pts.classification != CLASS_GROUND]
    else:
        las = laspy.read(AHN3)
        xyz = np.column_stack([las.x, las.y, las.z])[np.asarray(las.classification) != 2]
    a = extract_roof_planes(xyz, RoofPlaneParams(seed=3), backend="numba")
    b = extract_roof_planes(xyz, RoofPlaneParams(seed=3), backend="numpy")
    np.testing.assert_array_equal(a.plane_id, b.plane_id)
    assert a.n_candidates == b.n_candidates and len(a.planes) == len(b.planes) > 5
    for p, r in zip(a.planes, b.planes):
        np.testing.assert_array_equal(p.params, r.params)
        np.testing.assert_array_equal(p.covariance, r.covariance)
        np.testing.assert_array_equal(p.outline, r.outline)


def test_jacobi_normals_against_lapack():
    rng = np.random.default_rng(4)
    m = rng.normal(size=(500, 3, 8))
    cov = m @ m.transpose(0, 2, 1)
    cov[:50] = np.diag([4.0, 1.0, 0.0])  # already diagonal, one zero eigenvalue
    nx, ny, nz = _jacobi_normals(cov[:, 0, 0], cov[:, 0, 1], cov[:, 0, 2], cov[:, 1, 1],
                                 cov[:, 1, 2], cov[:, 2, 2])  # fmt: skip
    normal = np.column_stack([nx, ny, nz])
    _, vec = np.linalg.eigh(cov)
    ref = vec[:, :, 0] * np.where(vec[:, 2:3, 0] < 0, -1.0, 1.0)
    np.testing.assert_allclose(normal, ref, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(normal, axis=1), 1.0, atol=1e-12)
    # the region normals' two paths (numpy and numba) give the same bits, zero and huge or
    # tiny matrices included
    cov[50:60] = 0.0
    cov[60:70] *= 1e-300
    cov[70:80] *= 1e150
    np.testing.assert_array_equal(_eig_normals(cov), _eig_normals(cov, True))


def test_counting_order_is_the_coordinate_lexsort_and_backend_names():
    """The compiled counting sort orders each key's points by x, y, z (then index: exact
    duplicates and ties in x on a coarse lattice), as numpy's lexsort."""
    rng = np.random.default_rng(1)
    key = rng.integers(0, 50, 10_000)
    xyz = rng.integers(0, 4, (10_000, 3)).astype(float)
    order, start = compiled.counting_order(key, 50, xyz)
    np.testing.assert_array_equal(order, np.lexsort((xyz[:, 2], xyz[:, 1], xyz[:, 0], key)))
    np.testing.assert_array_equal(np.diff(start), np.bincount(key, minlength=50))
    with pytest.raises(InputError, match="backend"):
        extract_roof_planes(np.zeros((50, 3)), backend="fortran")
