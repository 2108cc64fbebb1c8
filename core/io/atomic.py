"""Writing files so that nothing is ever half written, and a job's outputs all or none.

Every file the core writes goes through :func:`atomic_path` (a temporary name in the target's
folder, moved into place with ``os.replace`` once complete) or :func:`atomic_write` (the same,
as an open file). A job's whole set of outputs goes through :class:`OutputSet`: each output is
written under a temporary name and the set is moved into place only when every output is
complete, after the job has refused any output path that is one of its inputs.

Temporary files are hidden (``.<stem>.<random>.part<suffix>``), created with the mode the final file
should have (the existing file's mode, else the process umask), and removed on any error,
including ``KeyboardInterrupt``.
"""

from __future__ import annotations

import contextlib
import os
import re
import tempfile
import time
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import IO, Any, Union

from ..errors import InputError

PathLike = Union[str, "os.PathLike[str]"]
TEMP_SUFFIX = ".part"


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def final_mode(path: PathLike) -> int:
    """Permission bits a file written at ``path`` should get: the existing file's, else 0666
    less the umask (what ``open()`` would give)."""
    try:
        return os.stat(path).st_mode & 0o777
    except OSError:
        return 0o666 & ~_umask()


def _temp_name(target: Path) -> str:
    """A new empty hidden file next to ``target`` that keeps its extension (writers such as
    laspy, GDAL and OpenCV choose the format by it): ``.name.<random>.part.tif``."""
    fd, tmp = tempfile.mkstemp(
        prefix=f".{target.stem}.", suffix=TEMP_SUFFIX + target.suffix, dir=target.parent
    )
    os.close(fd)
    return tmp


def _sidecars(tmp: str) -> list[tuple[str, str]]:
    """Files a writer put beside the temporary ``tmp`` (``tmp.aux.xml``...): (path, extension)."""
    folder, name = os.path.split(tmp)
    try:
        found = [f for f in os.listdir(folder or ".") if f.startswith(name + ".")]
    except OSError:
        return []
    return [(os.path.join(folder, f), f[len(name) :]) for f in found]


def _os_error(exc: OSError, path: PathLike) -> InputError:
    reason = exc.strerror or str(exc)
    return InputError(f"cannot write: {reason}", path=str(path))


@contextlib.contextmanager
def atomic_path(path: PathLike) -> Iterator[str]:
    """A temporary file name next to ``path``; moved onto ``path`` when the block succeeds.

    For writers that need a file name (laspy, GDAL). The folder is created when missing. OS
    errors become :class:`InputError` naming ``path``.

    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> with atomic_path(folder / "a.txt") as tmp:
    ...     _ = pathlib.Path(tmp).write_text("done")
    >>> (folder / "a.txt").read_text(), sorted(p.name for p in folder.iterdir())
    ('done', ['a.txt'])
    """
    target = Path(path)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        if target.is_dir():
            raise IsADirectoryError(21, "is a folder")
        mode = final_mode(target)
        tmp = _temp_name(target)
    except OSError as exc:
        raise _os_error(exc, path) from exc
    try:
        yield tmp
        os.chmod(tmp, mode)
        os.replace(tmp, target)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise _os_error(exc, path) from exc
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def atomic_write(
    path: PathLike, mode: str = "w", *, encoding: str | None = "utf-8", newline: str | None = None
) -> Iterator[IO[Any]]:
    """``open(path, mode)`` on a temporary file that replaces ``path`` when the block succeeds.

    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "b.csv"
    >>> with atomic_write(p, newline="") as fh:
    ...     _ = fh.write("x,y\\n")
    >>> p.read_text()
    'x,y\\n'
    """
    binary = "b" in mode
    with atomic_path(path) as tmp:
        with open(
            tmp, mode, encoding=None if binary else encoding, newline=None if binary else newline
        ) as fh:
            yield fh


def write_text_atomic(path: PathLike, text: str) -> None:
    """Write ``text`` (UTF-8, ``\\n`` line ends) to ``path`` atomically."""
    with atomic_write(path, newline="\n") as fh:
        fh.write(text)


def same_file(a: PathLike, b: PathLike) -> bool:
    """True when two paths name the same file (also through links or ``..``)."""
    try:
        if os.path.exists(a) and os.path.exists(b):
            return os.path.samefile(a, b)
    except OSError:
        pass
    return os.path.realpath(a) == os.path.realpath(b)


def _check_writable(name: str, target: Path) -> None:
    """Refuse, before any work, an output that cannot be written: a folder in its place, a
    file where a folder of its path should be, or a folder without write permission."""
    if target.is_dir():
        raise InputError(f"{name}: {target} is a folder; give a file name")
    folder = target.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        raise InputError(f"{name}: cannot write {target}: {folder} is a file, not a folder")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(f"{name}: cannot write {target}: no permission to write in {folder}")


class OutputSet:
    """The output files of one job, committed together.

    ``outputs`` maps a parameter name to its path (None or "" when not requested); ``inputs``
    maps parameter names to the input files. The constructor refuses (InputError) an output
    that is an input or another output, or that cannot be written (a folder, a file on its
    path, a folder without write permission), before anything is read. The job writes each output
    through :meth:`path` (a temporary name) and the caller calls :meth:`commit` once the job
    succeeded, or :meth:`discard` (also the effect of leaving the ``with`` block by an error).
    Temporaries of the outputs older than an hour, which only a killed process leaves behind,
    are removed first (:func:`remove_stale_temporaries`).

    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> with OutputSet({"A": d / "a.txt", "B": d / "b.txt"}, {}) as out:
    ...     _ = pathlib.Path(out.path("A")).write_text("a")
    ...     _ = pathlib.Path(out.path("B")).write_text("b")
    ...     out.commit()
    >>> sorted(p.name for p in d.iterdir())
    ['a.txt', 'b.txt']
    """

    def __init__(
        self,
        outputs: Mapping[str, PathLike | None],
        inputs: Mapping[str, PathLike | Iterable[PathLike] | None],
    ) -> None:
        self.targets = {k: Path(v) for k, v in outputs.items() if v}
        self._temps: dict[str, str] = {}
        self._done = False
        files = []
        for name, value in inputs.items():
            if not value:
                continue
            many = value if isinstance(value, (list, tuple)) else [value]
            files += [(name, Path(v)) for v in many if v]
        for out_name, target in self.targets.items():
            for in_name, source in files:
                if same_file(target, source):
                    raise InputError(
                        f"{out_name} is the input {in_name} ({source}): an output never "
                        "overwrites an input; choose another file"
                    )
        names = list(self.targets)
        for i, a in enumerate(names):
            for b in names[i + 1 :]:
                if same_file(self.targets[a], self.targets[b]):
                    raise InputError(f"{a} and {b} are the same file ({self.targets[a]})")
        for name, target in self.targets.items():
            _check_writable(name, target)
        for target in self.targets.values():  # left by a killed run of this job (SIGKILL)
            remove_stale_temporaries(target)

    def __enter__(self) -> OutputSet:
        return self

    def __exit__(self, *exc: object) -> None:
        if not self._done:
            self.discard()

    def requested(self, name: str) -> bool:
        """True when the user asked for output ``name``."""
        return name in self.targets

    def target(self, name: str) -> Path:
        """The final path of output ``name``."""
        return self.targets[name]

    def path(self, name: str) -> str:
        """The temporary file to write output ``name`` to (same folder, same suffix)."""
        if name not in self._temps:
            target = self.targets[name]
            try:
                target.parent.mkdir(parents=True, exist_ok=True)
                if target.is_dir():
                    raise IsADirectoryError(21, "is a folder")
                tmp = _temp_name(target)
            except OSError as exc:
                raise _os_error(exc, target) from exc
            self._temps[name] = tmp
        return self._temps[name]

    def commit(self, names: Iterable[str] | None = None) -> None:
        """Move the written outputs (all, or ``names``) into place.

        When one move fails (or Ctrl+C or a stop signal comes in between), the outputs already
        moved get their previous content back (kept as hard links while committing), so the
        user finds the old set or the new one.
        """
        chosen = list(self._temps) if names is None else [n for n in names if n in self._temps]
        # (target, hard link to its old content or None, whether it existed), recorded before
        # the move so that an interruption right after it is undone too
        moved: list[tuple[Path, str | None, bool]] = []
        current: Path | None = None
        try:
            for name in chosen:
                tmp, current = self._temps[name], self.targets[name]
                existed = current.exists()
                backup = None
                if existed:
                    backup = _temp_name(current)
                    os.unlink(backup)
                    try:
                        os.link(current, backup)
                    except OSError:  # no hard links here: no restore for this file
                        backup = None
                os.chmod(tmp, final_mode(current))
                moved.append((current, backup, existed))
                os.replace(tmp, current)
                for side, ext in _sidecars(tmp):  # e.g. a GeoTIFF's .aux.xml
                    os.replace(side, str(current) + ext)
                del self._temps[name]
        except BaseException as exc:  # an OS error, or Ctrl+C / a stop signal mid-way
            for target, backup, existed in reversed(moved):
                if backup is not None:
                    os.replace(backup, target)
                elif not existed:
                    target.unlink(missing_ok=True)
            self.discard()
            if isinstance(exc, OSError):
                raise _os_error(exc, current or "output") from exc
            raise
        for _, backup, _ in moved:
            if backup is not None:
                Path(backup).unlink(missing_ok=True)
        if names is None:
            self._done = True

    def discard(self) -> None:
        """Remove every temporary file not yet committed."""
        for tmp in self._temps.values():
            Path(tmp).unlink(missing_ok=True)
            for side, _ in _sidecars(tmp):
                Path(side).unlink(missing_ok=True)
        self._temps.clear()
        self._done = True


def remove_stale_temporaries(path: PathLike, older_than_s: float = 3600.0) -> list[str]:
    """Remove the temporaries an interrupted writer left next to ``path``; their paths.

    A temporary of ``path`` is a file ``.<stem>.*.part<suffix>`` in its folder (the names
    :func:`atomic_path` and :class:`OutputSet` use), with any sidecar a writer put beside it
    (``.aux.xml``). Only those last modified more than ``older_than_s`` seconds ago are removed,
    so the fresh temporary of a writer still at work is left alone. Errors (a folder that
    does not exist, a file another process removed first) are ignored.

    >>> import os, tempfile, pathlib, time
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> names = (".dtm.k1.part.tif", ".dtm.k2.part.tif", ".dtm.v.k3.part.tif", "dtm.tif")
    >>> for name in names:
    ...     _ = (folder / name).write_text("")
    >>> hour_ago = time.time() - 3601
    >>> for name in names[0], names[2]:  # the first and the one of "dtm.v.tif" are old
    ...     os.utime(folder / name, (hour_ago, hour_ago))
    >>> [pathlib.Path(p).name for p in remove_stale_temporaries(folder / "dtm.tif")]
    ['.dtm.k1.part.tif']
    >>> sorted(p.name for p in folder.iterdir())
    ['.dtm.k2.part.tif', '.dtm.v.k3.part.tif', 'dtm.tif']
    """
    target = Path(path)
    # the random part of mkstemp's names has no dot, so "dtm.tif" never claims the
    # temporaries of "dtm.x.tif"; a sidecar adds its own extension after the suffix
    pattern = re.compile(
        rf"\.{re.escape(target.stem)}\.[^.]+{re.escape(TEMP_SUFFIX + target.suffix)}(\..+)?"
    )
    folder = str(target.parent) or "."
    try:
        names = sorted(os.listdir(folder))
    except OSError:
        return []
    limit = time.time() - float(older_than_s)
    removed = []
    for name in names:
        if not pattern.fullmatch(name):
            continue
        full = os.path.join(folder, name)
        try:
            if os.stat(full).st_mtime >= limit:
                continue
            os.unlink(full)
        except OSError:
            continue
        removed.append(full)
    return removed
