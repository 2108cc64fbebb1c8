"""core/io/atomic.py: file modes of the committed outputs, all-or-nothing commits (a failing
move restores the outputs already moved), discard on error, atomic_path on error."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.io.atomic import OutputSet, atomic_path, write_text_atomic


def _mode(path: Path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


def test_new_file_follows_the_umask_and_a_rewrite_keeps_the_mode(tmp_path):
    old = os.umask(0o022)
    try:
        new = tmp_path / "new.txt"
        write_text_atomic(new, "x")
        assert _mode(new) == 0o644  # mkstemp alone would give 0600
        kept = tmp_path / "kept.txt"
        kept.write_text("old")
        os.chmod(kept, 0o640)
        write_text_atomic(kept, "new")
        assert kept.read_text() == "new" and _mode(kept) == 0o640
    finally:
        os.umask(old)


def test_an_error_inside_atomic_path_keeps_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "a.csv"
    target.write_text("old")
    with pytest.raises(RuntimeError), atomic_path(target) as tmp:
        Path(tmp).write_text("half")
        raise RuntimeError("writer failed")
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv"]


def test_a_failing_move_restores_the_outputs_already_moved(tmp_path, monkeypatch):
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    a.write_text("old a")
    b.write_text("old b")
    real_replace = os.replace
    calls = []

    def replace(src, dst):  # the second output's move fails once (a full disk, a lost mount)
        calls.append(Path(dst))
        if Path(dst) == b and calls.count(b) == 1:
            raise OSError(28, "No space left on device")
        return real_replace(src, dst)

    out = OutputSet({"A": a, "B": b}, {})
    Path(out.path("A")).write_text("new a")
    Path(out.path("B")).write_text("new b")
    monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(InputError, match=r"b\.txt.*No space left"):
        out.commit()
    monkeypatch.setattr(os, "replace", real_replace)
    assert a in calls  # A had been moved, then put back
    assert (a.read_text(), b.read_text()) == ("old a", "old b")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt", "b.txt"]


def test_leaving_the_block_by_an_error_writes_nothing(tmp_path):
    with pytest.raises(ValueError), OutputSet({"A": tmp_path / "a.tif"}, {}) as out:
        Path(out.path("A")).write_bytes(b"partial")
        Path(out.path("A") + ".aux.xml").write_text("<sidecar/>")
        raise ValueError("job failed")
    assert list(tmp_path.iterdir()) == []


def test_an_output_that_is_an_input_through_a_link_is_refused(tmp_path):
    src = tmp_path / "cloud.laz"
    src.write_bytes(b"points")
    link = tmp_path / "alias.laz"
    link.symlink_to(src)
    with pytest.raises(InputError, match="OUT is the input IN"):
        OutputSet({"OUT": link}, {"IN": src})
    assert src.read_bytes() == b"points"
