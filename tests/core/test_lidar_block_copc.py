"""lidarblock on COPC input (core/io/tiles.py): a COPC file made by a real writer (copclib)
is detected and each tile reads only the octree nodes meeting its cell + buffer; the block is
the one the chunked path gives on the same file and on the same points as a plain LAZ."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("distributed")
pytest.importorskip("copclib")

from lidarphoto.core import cli
from lidarphoto.core.errors import InputError
from lidarphoto.core.io import tiles as tiles_mod
from lidarphoto.core.io.pointcloud import read_info
from lidarphoto.core.io.tiles import index_block, is_copc, read_buffered
from lidarphoto.core.jobs import lidar_block
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.simulation.block import write_las
from lidarphoto.core.simulation.copc import write_copc
from lidarphoto.core.simulation.town import simulate_town

TILE = 45.0  # m: 16 grid tiles over the 180 m town, borders through buildings
WINDOW = 6.0  # SMRF window (m): ground buffer 2 x 6 + 5 + 3 x 1 = 20 m
PARAMS = {"TILE_SIZE": TILE, "SMRF_WINDOW": WINDOW, "WORKERS": 2, "LOCAL_CLUSTER": "threads"}


def _points(folder) -> dict[int, tuple[float, float, float, int]]:
    """Every point of the output tiles by its simulated id (gps_time): x, y, z, class."""
    import laspy

    out = {}
    for f in sorted((folder / "tiles").glob("*.laz")):
        las = laspy.read(f)
        for row in zip(np.asarray(las.gps_time).astype(np.int64).tolist(), las.x, las.y,
                       las.z, np.asarray(las.classification).tolist()):  # fmt: skip
            assert row[0] not in out, row[0]  # every point once
            out[row[0]] = row[1:]
    return out


@pytest.fixture(scope="module")
def town(tmp_path_factory):
    """A simulated town (169 k points, 180 m) with 300 points moved onto tile borders,
    written as COPC (copclib) and as a plain LAZ (point ids in gps_time); the block run on the
    COPC, on the same COPC read in chunks (COPC detection off) and on the plain LAZ."""
    root = tmp_path_factory.mktemp("copc")
    _, pts = simulate_town(n_buildings=20, n_trees=16, density=5.0, seed=0)
    xyz = pts.xyz.copy()
    rng = np.random.default_rng(1)
    edge = rng.choice(len(xyz), 300, replace=False)
    axis = rng.integers(0, 2, 300)  # x or y onto the nearest multiple of the tile size
    xyz[edge, axis] = np.round(xyz[edge, axis] / TILE) * TILE
    xyz[edge[:20], 0] = np.round(xyz[edge[:20], 0] / TILE) * TILE  # some on tile corners
    xyz[edge[:20], 1] = np.round(xyz[edge[:20], 1] / TILE) * TILE
    layout = write_copc(root / "town.copc.laz", xyz, leaf_points=4000)
    write_las(root / "town.laz", xyz)
    runs = {}
    runs["copc"] = run_job(lidar_block, {"INPUT": str(root / "town.copc.laz"),
                                         "OUTPUT_FOLDER": str(root / "copc"), **PARAMS})
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(tiles_mod, "is_copc", lambda path: False)
        runs["chunks"] = run_job(lidar_block, {"INPUT": str(root / "town.copc.laz"),
                                               "OUTPUT_FOLDER": str(root / "chunks"),
                                               **PARAMS})  # fmt: skip
    runs["plain"] = run_job(lidar_block, {"INPUT": str(root / "town.laz"),
                                          "OUTPUT_FOLDER": str(root / "plain"), **PARAMS})
    reports = {k: json.loads((root / k / "block_report.json").read_text()) for k in runs}
    return {"root": root, "xyz": xyz, "layout": layout, "runs": runs, "reports": reports}


def test_the_copc_file_is_a_real_copc_read_by_laspy(town):
    """The test file is COPC for laspy's own reader (its octree: several levels)."""
    import laspy

    path = town["root"] / "town.copc.laz"
    assert is_copc(path) and not is_copc(town["root"] / "town.laz")
    assert town["layout"]["depth"] >= 2 and town["layout"]["nodes"] >= 20
    with laspy.CopcReader.open(path) as reader:
        pts = reader.query()  # all levels, whole extent
        ids = np.sort(np.asarray(pts.gps_time).astype(np.int64))
    assert np.array_equal(ids, np.arange(len(town["xyz"])))


def test_copc_is_read_by_query_and_plain_laz_in_chunks(town):
    """Every COPC tile decodes only the nodes near its cell: the points it keeps are exactly
    those in its half-open cell or its closed buffered box; the chunked reads decode the whole
    file for every tile."""
    n = len(town["xyz"])
    rep = town["reports"]
    nt = len(rep["copc"]["tiles"])
    assert rep["copc"]["copc_tiles"] == nt >= 25
    assert rep["chunks"]["copc_tiles"] == rep["plain"]["copc_tiles"] == 0
    for k in ("chunks", "plain"):
        assert all(t["points_decoded"] == n for t in rep[k]["tiles"])
    index = index_block(town["root"] / "town.copc.laz", tile_size=TILE)
    x, y = town["xyz"][:, 0], town["xyz"][:, 1]
    b = rep["copc"]["ground_buffer"]
    assert b == 20.0
    r = max(b, rep["copc"]["roof_buffer"])
    decoded = kept = 0
    for tile, t in zip(index.tiles, rep["copc"]["tiles"]):
        c = tile.cell
        # the stored coordinates are the simulated ones to the mm
        core = (x >= c[0] - 5e-4) & (x < c[2] - 5e-4) & (y >= c[1] - 5e-4) & (y < c[3] - 5e-4)
        near = (x >= c[0] - r) & (x <= c[2] + r) & (y >= c[1] - r) & (y <= c[3] + r)
        assert t["points"] == int(core.sum())
        assert abs(t["points_read"] - int((core | near).sum())) <= 5  # mm rounding at r
        assert t["points_read"] <= t["points_decoded"] < 0.6 * n, t
        decoded += t["points_decoded"]
        kept += t["points_read"]
    # the nodes decoded are those of the cell + buffer, plus the parts of the octree's
    # coarse nodes (as large as the tiles here) beyond it: 30 tiles keep 3.5 times the
    # file's points and decode 8.4 times, where the chunked path decodes it 30 times
    assert kept < decoded < 3.0 * kept
    assert decoded < 0.35 * nt * n


def test_copc_tiles_equal_the_chunked_read_point_for_point(town):
    """read_buffered by query and by streaming the same file: the same points, ids, order
    and core flags for every tile (points on the cell edges included)."""
    import dataclasses

    index = index_block(town["root"] / "town.copc.laz", tile_size=TILE)
    chunked = dataclasses.replace(
        index, tiles=[dataclasses.replace(t, copc=False) for t in index.tiles])
    on_edge = 0
    for i, tile in enumerate(index.tiles):
        a = read_buffered(index, i, 20.0)
        b = read_buffered(chunked, i, 20.0)
        assert a.decoded < b.decoded == len(town["xyz"])
        for k in a.arrays:
            assert np.array_equal(a.arrays[k], b.arrays[k]), (tile.name, k)
        ra, rb = np.concatenate(a.records.chunks), np.concatenate(b.records.chunks)
        assert np.array_equal(ra, rb)
        xa = a.arrays["x"][a.arrays["core"]]
        on_edge += int(np.sum((xa == tile.cell[0]) | (a.arrays["y"][a.arrays["core"]]
                                                       == tile.cell[1])))  # fmt: skip
    assert on_edge >= 100  # the moved points sit exactly on the borders


def test_the_block_is_the_same_from_copc_chunks_and_plain_laz(town):
    """Same points once each, same ground classes, planes, LCPs and lines: the COPC run and the
    chunked run of the same file give identical tables; the plain LAZ (other file order) the
    same classes and the same planes and control to rounding."""
    from lidarphoto.core.io.planes import read_planes_csv

    root, n = town["root"], len(town["xyz"])
    pts = {k: _points(root / k) for k in ("copc", "chunks", "plain")}
    for k, p in pts.items():
        assert sorted(p) == list(range(n)), k
    assert pts["copc"] == pts["chunks"]
    cls = {k: np.array([p[i][3] for i in range(n)]) for k, p in pts.items()}
    assert np.array_equal(cls["copc"], cls["plain"])
    assert int((cls["copc"] == 2).sum()) > 0.4 * n  # a real ground filter ran
    for name in ("planes.csv", "lcps.csv", "lines.csv"):
        assert (root / "copc" / name).read_text() == (root / "chunks" / name).read_text()
    res = {k: r.results for k, r in town["runs"].items()}
    for key in ("POINT_COUNT", "GROUND_COUNT", "PLANE_COUNT", "LCP_COUNT", "LINE_COUNT"):
        assert res["copc"][key] == res["plain"][key] == res["chunks"][key], key
    assert res["copc"]["PLANE_COUNT"] >= 40 and res["copc"]["LCP_COUNT"] >= 10
    mine, ref = read_planes_csv(root / "copc" / "planes.csv"), read_planes_csv(
        root / "plain" / "planes.csv")  # fmt: skip
    for p in ref:
        angle = [np.degrees(np.arccos(min(1.0, abs(float(p.normal @ q.normal))))) for q in mine]
        k = int(np.argmin(angle))
        assert angle[k] < 0.3 and abs(mine[k].distance(p.centroid)[0]) < 0.005, p.id


def test_output_tiles_are_plain_laz_with_the_crs(town):
    """The COPC's records (info, hierarchy) are not copied into the output tiles; its WKT CRS
    (an EVLR in the COPC) is."""
    tile = sorted((town["root"] / "copc" / "tiles").glob("*.laz"))[5]
    assert not is_copc(tile)
    info = read_info(tile)
    assert info.crs is not None and info.crs.to_epsg() == 7415


def test_a_truncated_copc_is_reported_by_name(town, tmp_path, capsys):
    """One truncated COPC file: refused by name before any task. A folder of two COPC tiles:
    the west one reads its neighbour's buffer by query; with the east one truncated, the west
    one finishes, the east one is reported by name (its hierarchy is past the end of the
    file), the block is incomplete."""
    data = (town["root"] / "town.copc.laz").read_bytes()
    bad = tmp_path / "broken.copc.laz"
    bad.write_bytes(data[: len(data) // 2])
    with pytest.raises(InputError, match=r"broken\.copc\.laz"):
        index_block(bad, tile_size=TILE)
    folder = tmp_path / "tiles"
    folder.mkdir()
    xyz = town["xyz"]
    west = xyz[:, 0] < 85090.0
    write_copc(folder / "a_west.copc.laz", xyz[west], leaf_points=8000)
    write_copc(folder / "b_east.copc.laz", xyz[~west], leaf_points=8000)
    index = index_block(folder)
    assert [t.copc for t in index.tiles] == [True, True]
    buf = read_buffered(index, 0, 20.0)
    assert buf.decoded < len(xyz)  # all of its own file, a strip of its neighbour's
    assert not buf.missing and buf.n_core == int(west.sum())
    east = folder / "b_east.copc.laz"
    east.write_bytes(east.read_bytes()[: east.stat().st_size * 2 // 3])
    code = cli.main(["lidarblock", "--input", str(folder), "--output-folder",
                     str(tmp_path / "out"), "--smrf-window", str(WINDOW), "--workers", "1",
                     "--local-cluster", "threads"])  # fmt: skip
    assert code == lidar_block.INCOMPLETE_EXIT
    assert "b_east.copc" in capsys.readouterr().out
    report = json.loads((tmp_path / "out" / "block_report.json").read_text())
    assert [t["name"] for t in report["failed_tiles"]] == ["b_east.copc"]
    assert "truncated COPC" in report["failed_tiles"][0]["error"]
    good = report["tiles"][0]
    assert good["ok"] and good["points"] == int(west.sum())
