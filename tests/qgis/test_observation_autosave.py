"""The picking dock's autosave (plugin.observation_store) keeps the observation file's mode,
writes what the core's writer writes, and cleans up the temporaries a killed save leaves.

The kill is real: a child Python saves a large table over and over through the store and is
killed with SIGKILL while a temporary exists (mid-write); the file must then be a complete
table (the one before), and the next opening of the file by the store must remove the
temporary once it is older than a save can take (a younger one may be another QGIS saving).
"""

from __future__ import annotations

import os
import signal
import stat
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import lidarphoto
import numpy as np
import pytest
from lidarphoto.core.io.observations import read_observations_csv, write_observations_csv
from lidarphoto.core.photo.observation_list import Observation
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.plugin.observation_store import STALE_TEMPORARY_S, ObservationStore

PACKAGE_PARENT = Path(lidarphoto.__file__).parent.parent  # (not resolved: it may be a link)


def _mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


def _table(n: int, seed: int = 0) -> ImageObservations:
    rng = np.random.default_rng(seed)
    return ImageObservations.from_arrays(
        [f"img{k % 7}" for k in range(n)],
        [f"T{k}" for k in range(n)],
        rng.uniform(0, 6000, (n, 2)),
        np.full(n, 0.5),
        ["tie"] * n,
        [str(k % 50) for k in range(n)],
    )


@pytest.fixture()
def umask():
    """Set the process umask for a test, restore it afterwards."""
    old = os.umask(0o022)
    os.umask(old)

    def use(mask: int) -> None:
        os.umask(mask)

    yield use
    os.umask(old)


def _temporaries(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if ".part" in p.name)


def test_saves_keep_the_mode_and_leave_nothing_behind(tmp_path, umask, qgis_app):
    path = tmp_path / "obs.csv"
    write_observations_csv(path, _table(5))
    os.chmod(path, 0o644)
    umask(0o077)  # a new file would get 0600: the existing one must stay 0644
    store = ObservationStore()
    assert store.load(path) == 5
    store.add(Observation("img1", "T100", 10.5, 20.5, "tie", "3"))
    store.move(0, 1.25, 2.5)
    store.delete(1)
    store.undo()
    store.redo()
    assert store.save_count == 5 and store.last_error == ""
    assert _mode(path) == 0o644
    assert _temporaries(tmp_path) == [] and sorted(p.name for p in tmp_path.iterdir()) == [
        "obs.csv"
    ]
    # a file the store creates gets what the umask allows, as any new file
    for mask, mode in ((0o022, 0o644), (0o077, 0o600), (0o002, 0o664)):
        umask(mask)
        new = tmp_path / f"new_{mask:o}.csv"
        ObservationStore().load(new)
        assert _mode(new) == mode, (oct(mask), oct(_mode(new)))


def test_a_failed_save_names_the_file_and_keeps_the_rows(tmp_path, qgis_app):
    folder = tmp_path / "d"
    folder.mkdir()
    store = ObservationStore()
    store.load(folder / "obs.csv")
    (folder / "obs.csv").unlink()
    folder.rmdir()
    folder.write_text("a file where the folder was")  # (fails also for root)
    failed = []
    store.saveFailed.connect(failed.append)
    store.add(Observation("img1", "T1", 1.5, 2.5, "tie", "3"))
    assert len(failed) == 1 and str(folder / "obs.csv") in failed[0]
    assert len(store.rows) == 1 and store.last_error == failed[0]
    folder.unlink()
    folder.mkdir()
    store.add(Observation("img1", "T2", 3.5, 4.5, "tie", "3"))  # the next change retries
    assert store.last_error == "" and len(read_observations_csv(folder / "obs.csv")) == 2


def test_the_file_is_what_the_core_writer_writes(tmp_path, qgis_app):
    """Rows formatted once and kept (the autosave's speed) give the core writer's bytes, also
    for ids that need quoting, and read back to the same floats."""
    path = tmp_path / "obs.csv"
    store = ObservationStore()
    store.load(path)
    odd = [
        Observation('img "A", left', "T1", 0.1 + 0.2, 1e-7, "tie", "3"),
        Observation("img2", "P,2", 1234.5678901234567, 2.0, "paper", "roof 1"),
        Observation("img2", "C7", 3.0, 4.0, "lcp", "7", 0.25),
    ]
    for o in odd:
        store.add(o)
    store.move(1, 5.5, 6.75)
    expected = tmp_path / "expected.csv"
    write_observations_csv(expected, store.to_observations())
    assert path.read_bytes() == expected.read_bytes()
    back = ObservationStore()
    back.load(path)
    assert back.rows == store.rows


def test_kill_mid_write_then_open_removes_the_temporary(tmp_path, qgis_app):
    path = tmp_path / "obs.csv"
    write_observations_csv(path, _table(20, seed=1))
    os.chmod(path, 0o644)
    before = path.read_bytes()
    child = textwrap.dedent(
        f"""
        import sys
        sys.path.insert(0, {str(PACKAGE_PARENT)!r})
        from lidarphoto.core.photo.observation_list import Observation
        from lidarphoto.plugin.observation_store import ObservationStore
        store = ObservationStore()
        store.load({str(path)!r})
        # a large table: each save writes ~15 MB, long enough to be killed in the middle
        store.log.add([Observation("img%d" % (k % 9), "X%d" % k, 0.1 * k, 0.2 * k, "tie", "1")
                       for k in range(250000)])
        print("saving", flush=True)
        while True:
            store.save()
        """
    )
    folder = tmp_path
    left = []
    for _attempt in range(5):
        proc = subprocess.Popen(
            [sys.executable, "-c", child], stdout=subprocess.PIPE, stderr=subprocess.PIPE
        )
        try:
            assert proc.stdout.readline().strip() == b"saving", proc.stderr.read()
            t_end = time.monotonic() + 10.0
            while not _temporaries(folder) and time.monotonic() < t_end:
                time.sleep(0.001)
            os.kill(proc.pid, signal.SIGKILL)  # while a temporary exists: mid-write
        finally:
            proc.wait(30)
        assert proc.returncode == -signal.SIGKILL
        left = _temporaries(folder)
        if left:
            break
    assert len(left) == 1, left  # killed while writing (else: the file was complete)
    assert left[0].startswith(".obs.") and left[0].endswith(".part.csv")
    # the file is a complete table (the old one or a whole new one), its mode kept
    table = read_observations_csv(path)
    assert len(table) in (20, 250020)
    if len(table) == 20:
        assert path.read_bytes() == before
    assert _mode(path) == 0o644
    # the next opening, right away: a temporary this young may be another QGIS's save: kept
    temp = folder / left[0]
    store = ObservationStore()
    store.load(path)
    assert store.removed_temporaries == [] and temp.exists()
    # later (QGIS restarted): removed, the rows all there, nothing else touched
    old = time.time() - STALE_TEMPORARY_S - 1.0
    os.utime(temp, (old, old))
    other = folder / ".other.abc123.part.csv"  # a temporary of another file: not ours
    other.write_text("x")
    os.utime(other, (old, old))
    store = ObservationStore()
    assert store.load(path) == len(table)
    assert store.removed_temporaries == [str(temp)]
    assert _temporaries(folder) == [other.name]
    assert _mode(path) == 0o644


def test_control_rows_of_located_control_are_kept_and_saved_unchanged(tmp_path, qgis_app):
    """A file of locatecontrolpoints (type control, empty target) mixed with the dock's own
    rows: loaded without refusal, saved byte for byte as the core writer writes it, and an
    edit of another row leaves the control rows as they were."""
    path = tmp_path / "located.csv"
    table = ImageObservations.from_arrays(
        ["img1", "img2", "img1"], ["GCP12", "GCP12", "T1"],
        [[1523.4127, 988.2031], [210.75, 1990.125], [10.5, 20.5]], [0.15, 0.2, 0.5],
        ["control", "control", "tie"], ["", "", "3"],
    )  # fmt: skip
    write_observations_csv(path, table)
    original = path.read_bytes()
    store = ObservationStore()
    assert store.load(path) == 3
    assert store.save() and path.read_bytes() == original
    store.move(2, 11.5, 21.5)
    back = read_observations_csv(path)
    assert back.type == ("control", "control", "tie") and back.target_id[:2] == ("", "")
    np.testing.assert_array_equal(back.pixels[:2], table.pixels[:2])
    np.testing.assert_array_equal(back.sigma_px[:2], table.sigma_px[:2])
