"""The tiled LiDAR block on dask.distributed (core/jobs/lidar_block.py): inputs (folder, VPC,
one large file), buffers (classes equal to a whole-cloud run up to the documented rule),
planes merged across tile borders, control deduplicated, bad tiles, a killed worker, cancel."""

from __future__ import annotations

import functools
import json
import os
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("distributed")

from lidarphoto.core import cli
from lidarphoto.core.errors import Cancelled, CrsError
from lidarphoto.core.geometry.grid import Grid
from lidarphoto.core.io.planes import read_planes_csv
from lidarphoto.core.io.tiles import index_block, read_buffered, write_vpc
from lidarphoto.core.jobs import lidar_block
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.lidar.block import ground_buffer
from lidarphoto.core.lidar.control import lidar_control
from lidarphoto.core.lidar.ground_filter import ground_filter
from lidarphoto.core.lidar.ground_filter_params import SmrfParams
from lidarphoto.core.lidar.roof_planes import extract_roof_planes
from lidarphoto.core.simulation.block import town_tiles, write_las

TILE = 60.0  # m: the town's 30 m cells put tile borders through buildings
THREADS = {"WORKERS": 2, "LOCAL_CLUSTER": "threads"}


def _read_tiles(folder: Path) -> tuple[np.ndarray, np.ndarray]:
    """(ids, classes) of every point of the output tiles."""
    import laspy

    ids, cls = [], []
    for f in sorted((folder / "tiles").glob("*.laz")):
        las = laspy.read(f)
        ids.append(np.asarray(las.gps_time).astype(np.int64))
        cls.append(np.asarray(las.classification))
    return np.concatenate(ids), np.concatenate(cls)


@pytest.fixture(scope="module")
def block(tmp_path_factory):
    """A simulated town (75 k points) in 14 tiles of 60 m, the block run on it (2 thread
    workers), and the whole-cloud ground filter of the same points."""
    root = tmp_path_factory.mktemp("block")
    xyz, _, files = town_tiles(root / "tiles", TILE, density=4.0)
    out = root / "out"
    result = run_job(lidar_block, {"INPUT": str(root / "tiles"), "OUTPUT_FOLDER": str(out),
                                   **THREADS})  # fmt: skip
    whole = ground_filter(xyz[:, 0], xyz[:, 1], xyz[:, 2], SmrfParams())
    return {"root": root, "xyz": xyz, "files": files, "out": out, "result": result,
            "whole": whole}  # fmt: skip


def test_every_point_once_with_its_id(block):
    ids, _ = _read_tiles(block["out"])
    assert len(ids) == len(block["xyz"]) == block["result"].results["POINT_COUNT"]
    assert np.array_equal(np.sort(ids), np.arange(len(block["xyz"])))
    report = json.loads((block["out"] / "block_report.json").read_text())
    assert report["complete"] is True and block["result"].exit_code == 0
    assert report["ground_buffer"] == 44.0  # 2 x 18 m + 5 m + 3 x 1 m
    # the roof planes' second pass ran on the client and left no scratch points behind
    assert report["second_pass_s"] >= 0.0
    assert sorted(p.name for p in block["out"].iterdir() if p.name.startswith(".")) == []
    vpc = json.loads((block["out"] / "block.vpc").read_text())
    assert len(vpc["features"]) == len(block["files"])
    assert sum(f["properties"]["pc:count"] for f in vpc["features"]) == len(ids)


def test_ground_classes_equal_a_whole_cloud_run_up_to_the_buffer_rule(block):
    """>= 99.9 % of the points get the whole run's ground class; every point that differs
    lies where the two DTMs differ (the pull-push fill under objects depends on the grid's
    origin, which is the tile's), never where the tile's DTM equals the whole one."""
    ids, cls = _read_tiles(block["out"])
    whole = block["whole"].ground[ids]
    tiled = cls == 2
    by_id = np.zeros(len(ids), bool)
    by_id[ids] = tiled
    agree = float((whole == tiled).mean())
    assert agree >= 0.999, agree
    differ = ids[whole != tiled]
    # the explanation: re-run the tiles holding them as the block does, compare the DTMs
    index = index_block(block["root"] / "tiles")
    buffer = ground_buffer(SmrfParams())
    xyz = block["xyz"]
    gw = block["whole"]
    grid_w = Grid(gw.geotransform[0], gw.geotransform[3], gw.geotransform[1], *gw.dtm.shape)
    explained = 0
    for i, tile in enumerate(index.tiles):
        mine = differ[(differ >= tile.offset) & (differ < tile.offset + tile.count)]
        if not len(mine):
            continue
        buf = read_buffered(index, i, buffer)
        a = buf.arrays
        t = ground_filter(a["x"], a["y"], a["z"], SmrfParams())
        grid_t = Grid(t.geotransform[0], t.geotransform[3], t.geotransform[1], *t.dtm.shape)
        # the DTM at the point and one cell around it (the slope term's gradient)
        gap = np.zeros(len(mine))
        for dx, dy in ((0, 0), (-1, 0), (1, 0), (0, -1), (0, 1)):
            p = xyz[mine] + [dx * grid_w.cell, dy * grid_w.cell, 0.0]
            dw = grid_w.bilinear(gw.dtm, p[:, 0], p[:, 1])
            dt = grid_t.bilinear(t.dtm, p[:, 0], p[:, 1])
            gap = np.maximum(gap, np.abs(dw - dt))
        assert np.all(gap > 1e-3), (tile.name, gap)
        # and the tile run itself gives the block's class (the block is this run)
        pos = np.searchsorted(a["id"][: buf.n_core], mine)
        assert np.array_equal(t.ground[pos], by_id[mine])
        explained += len(mine)
    assert explained == len(differ)


def test_planes_cut_by_borders_are_merged_and_control_deduplicated(block):
    """The block's planes are the whole cloud's: same count, each whole plane matched within
    0.3 degrees and 5 mm; some planes were cut by a border (pieces from several tiles) and were
    refitted from all their points; LCPs and lines are those of a whole-cloud run, once each."""
    xyz, whole = block["xyz"], block["whole"]
    ng = ~whole.ground & ~whole.low_outlier
    ref = extract_roof_planes(xyz[ng])
    mine = read_planes_csv(block["out"] / "planes.csv")
    assert len(mine) == len(ref.planes) >= 20
    for p in ref.planes:
        angle = [np.degrees(np.arccos(min(1.0, abs(float(p.normal @ q.normal))))) for q in mine]
        k = int(np.argmin(angle))
        assert angle[k] < 0.3 and abs(mine[k].distance(p.centroid)[0]) < 0.005, p.id
    report = json.loads((block["out"] / "block_report.json").read_text())
    pieces = sum(t["plane_pieces"] for t in report["tiles"])
    assert pieces > len(mine)  # some planes came in pieces from several tiles
    ctrl = lidar_control(ref.planes, xyz[ng], ref.plane_id)
    res = block["result"].results
    assert res["LCP_COUNT"] == len(ctrl.points) and res["LINE_COUNT"] == len(ctrl.lines)
    import csv

    with open(block["out"] / "lcps.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    lcp = np.array([[float(r["X"]), float(r["Y"]), float(r["Z"])] for r in rows])
    ref_lcp = np.array([p.xyz for p in ctrl.points])
    dist = np.linalg.norm(lcp[:, None] - ref_lcp[None], axis=2)
    assert np.all(dist.min(axis=1) < 0.05)  # each block LCP is a whole-run LCP
    assert len(set(dist.argmin(axis=1).tolist())) == len(lcp)  # never twice


def test_vpc_and_one_large_file_give_the_same_block(block, tmp_path):
    root = block["root"]
    index = index_block(root / "tiles")
    items = [{"name": t.name, "href": f"../tiles/{Path(t.path).name}", "count": t.count,
              "bbox": (*t.box[:2], 0.0, *t.box[2:], 10.0)} for t in index.tiles]  # fmt: skip
    (tmp_path / "v").mkdir()
    write_vpc(tmp_path / "v" / "in.vpc", items, index.info.crs.to_wkt())
    shutil.copytree(root / "tiles", tmp_path / "tiles")
    vindex = index_block(tmp_path / "v" / "in.vpc")
    assert [t.name for t in vindex.tiles] == [t.name for t in index.tiles]
    run_job(lidar_block, {"INPUT": str(tmp_path / "v" / "in.vpc"),
                          "OUTPUT_FOLDER": str(tmp_path / "o1"), **THREADS})  # fmt: skip
    ids0, cls0 = _read_tiles(block["out"])
    ids1, cls1 = _read_tiles(tmp_path / "o1")
    assert np.array_equal(ids0, ids1) and np.array_equal(cls0, cls1)
    # one large file cut into 60 m grid tiles, read in chunks
    write_las(tmp_path / "one.laz", block["xyz"])
    res = run_job(lidar_block, {"INPUT": str(tmp_path / "one.laz"), "TILE_SIZE": TILE,
                                "OUTPUT_FOLDER": str(tmp_path / "o2"), **THREADS})  # fmt: skip
    ids2, cls2 = _read_tiles(tmp_path / "o2")
    assert np.array_equal(np.sort(ids2), np.arange(len(block["xyz"])))
    assert res.results["TILE_COUNT"] >= 10
    whole = block["whole"].ground[ids2]
    assert float((whole == (cls2 == 2)).mean()) >= 0.999


def test_bad_tiles_reported_by_name_the_rest_finishes(block, tmp_path, capsys):
    tiles = tmp_path / "tiles"
    shutil.copytree(block["root"] / "tiles", tiles)
    victim = sorted(tiles.glob("*.laz"))[4]
    data = victim.read_bytes()
    victim.write_bytes(data[: len(data) // 2])  # header fine, points truncated
    (tiles / "tile_zz_garbage.laz").write_bytes(b"not a LAZ file at all" * 10)
    code = cli.main(["lidarblock", "--input", str(tiles), "--output-folder",
                     str(tmp_path / "out"), "--workers", "2",
                     "--local-cluster", "threads"])  # fmt: skip
    assert code == lidar_block.INCOMPLETE_EXIT == 3
    out = capsys.readouterr().out
    assert "INCOMPLETE" in out and victim.stem in out and "tile_zz_garbage" in out
    report = json.loads((tmp_path / "out" / "block_report.json").read_text())
    assert report["complete"] is False
    assert {t["name"] for t in report["failed_tiles"]} == {victim.stem, "tile_zz_garbage"}
    ids, _ = _read_tiles(tmp_path / "out")
    full = index_block(block["root"] / "tiles")
    n_victim = next(t.count for t in full.tiles if t.name == victim.stem)
    assert len(ids) == len(np.unique(ids)) == len(block["xyz"]) - n_victim
    # the neighbours of the broken tile say their buffer was incomplete
    assert any(t["buffer_incomplete"] for t in report["tiles"] if t["ok"])


def test_tiles_in_different_crss_are_refused(tmp_path):
    xyz = np.random.default_rng(0).uniform(0, 50, (200, 3)) + [85000, 447000, 0]
    write_las(tmp_path / "a.laz", xyz, epsg=7415)
    write_las(tmp_path / "b.laz", xyz + [50, 0, 0], epsg=32631)
    with pytest.raises(CrsError, match="different CRSs"):
        index_block(tmp_path)


def test_cancel_stops_the_tasks_and_writes_nothing(block, tmp_path):
    calls = []

    def stop():
        calls.append(1)
        return len(calls) > 1

    with pytest.raises(Cancelled):
        run_job(lidar_block, {"INPUT": str(block["root"] / "tiles"),
                              "OUTPUT_FOLDER": str(tmp_path / "out"), **THREADS},
                should_stop=stop)  # fmt: skip
    assert not (tmp_path / "out").exists()
    assert [p.name for p in tmp_path.iterdir()] == []  # no staging folder left


def _kill_once(index, i, settings, staging, marker):
    """The tile task, except that the first run of tile 1 kills its worker process."""
    if i == 1 and not os.path.exists(marker):
        Path(marker).write_text(str(os.getpid()))
        os._exit(1)
    return lidar_block.process_tile(index, i, settings, staging)


def test_a_killed_worker_task_is_rerun_without_lost_or_duplicated_points(block, tmp_path):
    """A real process cluster (2 workers): the worker running tile 1 dies; dask's nanny
    restarts it and the scheduler runs the task again; the block has every point once."""
    import cloudpickle
    from distributed import Client, LocalCluster

    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    index = index_block(block["root"] / "tiles")
    v = lidar_block.SPEC  # the defaults, through the job's own settings
    from lidarphoto.core.jobs.spec import parse_values

    values = parse_values(v, {"INPUT": str(block["root"] / "tiles"),
                              "OUTPUT_FOLDER": str(tmp_path / "o")})  # fmt: skip
    settings = lidar_block.settings_from(values, index.info)
    marker = tmp_path / "killed"
    staging = tmp_path / "staging"
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:  # fmt: skip
        task = functools.partial(_kill_once, marker=str(marker))
        res = lidar_block.run_block(index, settings, str(staging), client, task=task)
    assert marker.exists()  # the worker was killed
    assert all(o.ok for o in res["outcomes"])
    ids, cls = _read_tiles(staging)
    assert np.array_equal(np.sort(ids), np.arange(len(block["xyz"])))
    ids0, cls0 = _read_tiles(block["out"])
    assert np.array_equal(ids, ids0) and np.array_equal(cls, cls0)
    assert not [p for p in (staging / "tiles").iterdir() if p.name.startswith(".")]


def test_an_existing_cluster_by_address_is_used_and_left_running(block, tmp_path):
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster:  # fmt: skip
        res = run_job(lidar_block, {"INPUT": str(block["root"] / "tiles"),
                                    "OUTPUT_FOLDER": str(tmp_path / "o"),
                                    "CLUSTER": cluster.scheduler_address})  # fmt: skip
        with Client(cluster) as client:  # still up: the job closed only its own client
            assert len(client.scheduler_info()["workers"]) == 2
    assert res.results["POINT_COUNT"] == len(block["xyz"])
    ids, cls = _read_tiles(tmp_path / "o")
    ids0, cls0 = _read_tiles(block["out"])
    assert np.array_equal(ids, ids0) and np.array_equal(cls, cls0)


def test_an_unreachable_cluster_is_an_input_error(block, tmp_path):
    from lidarphoto.core.errors import InputError

    with pytest.raises(InputError, match="CLUSTER"):
        run_job(lidar_block, {"INPUT": str(block["root"] / "tiles"),
                              "OUTPUT_FOLDER": str(tmp_path / "o"),
                              "CLUSTER": "tcp://127.0.0.1:9"})  # fmt: skip
    assert not (tmp_path / "o").exists()
