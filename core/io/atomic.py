"""Writing files so that nothing is ever half written, and a job's outputs all or none.

Every file the core writes goes through :func:`atomic_path` (a temporary name in the target's
folder, moved into place with ``os.replace`` once complete) or :func:`atomic_write` (the same,
as an open file). A job's whole set of outputs goes through :class:`OutputSet`: each output is
written under a temporary name and the set is moved into place only when every output is
complete, after :func:`check_outputs` has refused any output that would overwrite a file the
job reads (compared as the files themselves: links, ``..`` and the case of a case-insensitive
file system resolved; folders expanded to the files the job reads from them; the files GDAL
reads beside a raster).

Temporary files are hidden (``.<stem>.<token>.part<suffix>``), created with the mode the final
file should have (the existing file's mode, else the process umask), and removed on any error,
including ``KeyboardInterrupt``. The token names the process that made the file (its id and a
hash of the host name, then mkstemp's random part), so that the next job writing in the folder
removes at once what a killed process left (:func:`remove_dead_temporaries`).
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import socket
import tempfile
import time
import zlib
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


#: Hash of this machine's name in temporary names: a process id is only compared on its host.
_HOST = f"{zlib.crc32(socket.gethostname().encode('utf-8', 'replace')) & 0xFFFFFF:06x}"
#: The token of a temporary name: ``p<pid>h<host hash>r<random>``.
_TOKEN = re.compile(r"p(\d+)h([0-9a-f]{6})r[^.]+")
#: Any temporary name (also the temporary of a temporary, ``..g.<t1>.part.<t2>.part.laz``, and
#: a writer's sidecar of it, ``.d.<t>.part.tif.aux.xml``): (base without sidecar, token).
_ANY_TEMP = re.compile(rf"(\..+\.([^.]+){re.escape(TEMP_SUFFIX)}(?:\.[^.]+)?)(\..+)?")
#: Temporaries this process made and has not yet moved or removed (threads of one process,
#: e.g. QGIS, share its id).
_LIVE: set[str] = set()


def _temp_name(target: Path) -> str:
    """A new empty hidden file next to ``target`` that keeps its extension (writers such as
    laspy, GDAL and OpenCV choose the format by it): ``.name.p<pid>h<host>r<random>.part.tif``."""
    fd, tmp = tempfile.mkstemp(
        prefix=f".{target.stem}.p{os.getpid()}h{_HOST}r",
        suffix=TEMP_SUFFIX + target.suffix,
        dir=target.parent,
    )
    os.close(fd)
    _LIVE.add(os.path.abspath(tmp))
    return tmp


def temp_folder(target: Path) -> Path:
    """A new hidden folder next to ``target`` (a folder to be) with the name of a temporary,
    ``.name.p<pid>h<host>r<random>.part``: :func:`remove_dead_temporaries` removes it once its
    process is gone; :func:`_forget` it when it is moved into place or removed."""
    tmp = tempfile.mkdtemp(
        prefix=f".{target.name}.p{os.getpid()}h{_HOST}r", suffix=TEMP_SUFFIX, dir=target.parent
    )
    _LIVE.add(os.path.abspath(tmp))
    return Path(tmp)


def _forget(tmp: str) -> None:
    """``tmp`` is no longer a temporary of this process (moved into place or removed)."""
    _LIVE.discard(os.path.abspath(tmp))


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
    finally:
        _forget(tmp)


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


def folder_files(folder: Union[str, os.PathLike], *names: str) -> dict[str, Path]:
    """The paths of the files ``names`` in ``folder`` (made, with its parents, if missing),
    each by its name without the extension: the files a simulator writes and returns.

    >>> root = Path(tempfile.mkdtemp())
    >>> {k: p.name for k, p in folder_files(root / "sim", "camera.json", "eo.csv").items()}
    {'camera': 'camera.json', 'eo': 'eo.csv'}
    >>> (root / "sim").is_dir(), shutil.rmtree(root)
    (True, None)
    """
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    return {Path(name).stem: out / name for name in names}


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


# ----------------------------------------------------------------------------- the guard
#: Endings of the files read as rasters through GDAL, which reads the files beside them too.
RASTER_SUFFIXES = (
    ".tif",
    ".tiff",
    ".jpg",
    ".jpeg",
    ".png",
    ".jp2",
    ".img",
    ".bmp",
    ".gif",
    ".vrt",
    ".asc",
)
#: What GDAL reads beside a raster ``x.tif``: ``x.tif`` + these.
_RASTER_SIDECARS = ((".aux.xml", "its metadata"), (".ovr", "its overviews"), (".msk", "its mask"))


def _world_files(path: Path) -> tuple[str, ...]:
    """Names of the georeferencing files GDAL takes for ``path``: ``x.tfw``, ``x.tifw``,
    ``x.wld`` (world files) and ``x.tab`` (MapInfo)."""
    ext = path.suffix
    return (
        f"{path.stem}.{ext[1]}{ext[-1]}w",
        f"{path.stem}{ext}w",
        f"{path.stem}.wld",
        f"{path.stem}.tab",
    )


def _names_in(folder: Path, cache: dict[Path, dict[str, str]]) -> dict[str, str]:
    """Lower-case name -> name of the files in ``folder`` (read once)."""
    if folder not in cache:
        try:
            cache[folder] = {n.lower(): n for n in os.listdir(folder)}
        except OSError:
            cache[folder] = {}
    return cache[folder]


def files_read(
    inputs: Mapping[str, PathLike | Iterable[PathLike] | None],
    suffixes: Mapping[str, Iterable[str]] | None = None,
) -> list[tuple[str, Path, str]]:
    """Every existing file the inputs make a job read: (input name, file, how it is read).

    A folder stands for its files (not recursive) with the endings ``suffixes[name]`` (every
    file when not given), as the job's reader lists them; a raster (:data:`RASTER_SUFFIXES`)
    brings the files GDAL reads beside it (``.aux.xml``, ``.ovr``, ``.msk``, world files; any
    case). "How" is "" for a file named, else the words of the message.

    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> for name in ("a.tif", "a.tfw", "notes.txt"):
    ...     _ = (d / name).write_text("")
    >>> for name, f, how in files_read({"IMAGES": [d]}, {"IMAGES": [".tif"]}):
    ...     print(name, f.name, how.replace(str(d), "<d>"))
    IMAGES a.tif , read from the folder <d>
    IMAGES a.tfw , the world file of <d>/a.tif
    """
    listing: dict[Path, dict[str, str]] = {}
    out: list[tuple[str, Path, str]] = []
    for name, value in inputs.items():
        if not value:
            continue
        many = [value] if isinstance(value, (str, os.PathLike)) else list(value)
        ends = tuple(e.lower() for e in (suffixes or {}).get(name, ()))
        for raw in many:
            if not raw or not isinstance(raw, (str, os.PathLike)):
                continue  # an object the QGIS adapter made from a layer
            p = Path(raw)
            if p.is_dir():
                files = [
                    (p / f, f", read from the folder {p}")
                    for f in sorted(os.listdir(p))
                    if (p / f).is_file() and (not ends or Path(f).suffix.lower() in ends)
                ]
            elif p.is_file():
                files = [(p, "")]
            else:
                continue  # the job's reader names a missing file
            for f, how in files:
                out.append((name, f, how))
                if f.suffix.lower() not in RASTER_SUFFIXES:
                    continue
                names = _names_in(f.parent, listing)
                sides = [(f.name + ext, f"{what} of {f}") for ext, what in _RASTER_SIDECARS]
                sides += [(w, f"the world file of {f}") for w in _world_files(f)]
                for side, what in sides:
                    found = names.get(side.lower())
                    if found is not None and found != f.name:
                        out.append((name, f.parent / found, f", {what}"))
    return out


def _identity(path: Path) -> tuple[int, int] | None:
    """(device, inode) of an existing file: the same for every name of it (links, ``..``,
    another case on a case-insensitive file system); None when there is none."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_dev, st.st_ino)


def check_outputs(
    outputs: Mapping[str, PathLike],
    inputs: Mapping[str, PathLike | Iterable[PathLike] | None],
    suffixes: Mapping[str, Iterable[str]] | None = None,
    folders: Mapping[str, PathLike] | None = None,
) -> None:
    """Refuse (InputError) an output that would overwrite a file the job reads.

    ``outputs``: name -> file the job writes (with the sidecars GDAL may write beside a
    raster); ``folders``: name -> a folder the job replaces as a whole (no input may lie in
    it); ``inputs`` and ``suffixes`` as :func:`files_read`. Files are compared as files
    (device and inode), so a link, ``..``, a folder named instead of its files or another
    case of the name on a case-insensitive file system changes nothing. Nothing is written.
    """
    reads = files_read(inputs, suffixes)
    by_id: dict[tuple[int, int] | None, tuple[str, Path, str]] = {}
    for name, f, how in reads:
        key = _identity(f)
        if key is not None:
            by_id.setdefault(key, (name, f, how))
    for out_name, target in outputs.items():
        target = Path(target)
        written = [(target, "")]
        if target.suffix.lower() in RASTER_SUFFIXES:
            written += [
                (Path(str(target) + ext), f" (with {target.name + ext}, {what})")
                for ext, what in _RASTER_SIDECARS
            ]
        for path, what in written:
            # folders of the path still missing are made before writing: "new/../x" is "x"
            hit = by_id.get(_identity(Path(os.path.realpath(path))))
            if hit is not None:
                in_name, source, how = hit
                raise InputError(
                    f"{out_name}{what} is the input {in_name} ({source}{how}): an output "
                    "never overwrites an input; choose another file"
                )
    for out_name, folder in (folders or {}).items():
        inside = os.path.realpath(folder)
        for in_name, f, how in reads:
            try:
                common = os.path.commonpath([os.path.realpath(f), inside])
            except ValueError:  # another drive
                continue
            if os.path.normcase(common) == os.path.normcase(inside):
                raise InputError(
                    f"{out_name} ({folder}) holds the input {in_name} ({f}{how}): the folder "
                    "is replaced as a whole when the job is done; choose another folder"
                )


class OutputSet:
    """The output files of one job, committed together.

    ``outputs`` maps a parameter name to its path (None or "" when not requested); ``inputs``
    maps parameter names to the input files or folders (``suffixes``: the file endings the job
    reads from a folder of that input; every file when not given). The constructor refuses
    (InputError) an output that would overwrite a file the job reads (:func:`check_outputs`)
    or another output, or that cannot be written (a folder, a file on its path, a folder
    without write permission), before anything is read. The job writes each output
    through :meth:`path` (a temporary name) and the caller calls :meth:`commit` once the job
    succeeded, or :meth:`discard` (also the effect of leaving the ``with`` block by an error).
    Temporaries only a killed process leaves behind are removed first: in the outputs'
    folders every one of a process that is gone (:func:`remove_dead_temporaries`), and those
    of the outputs older than an hour (:func:`remove_stale_temporaries`).

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
        suffixes: Mapping[str, Iterable[str]] | None = None,
    ) -> None:
        self.targets = {k: Path(v) for k, v in outputs.items() if v}
        self._temps: dict[str, str] = {}
        self._done = False
        check_outputs(self.targets, inputs, suffixes)
        names = list(self.targets)
        for i, a in enumerate(names):
            for b in names[i + 1 :]:
                if same_file(self.targets[a], self.targets[b]):
                    raise InputError(f"{a} and {b} are the same file ({self.targets[a]})")
        for name, target in self.targets.items():
            _check_writable(name, target)
        for folder in sorted({t.parent for t in self.targets.values()}):
            remove_dead_temporaries(folder)  # left by any killed job writing here
        for target in self.targets.values():  # left by a killed run of this job elsewhere
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
                    _forget(backup)
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
                _forget(tmp)
                del self._temps[name]
        except BaseException as exc:  # an OS error, or Ctrl+C / a stop signal mid-way
            for target, backup, existed in reversed(moved):
                if backup is not None:
                    # a no-op when the move never happened (both names are links to one file)
                    os.replace(backup, target)
                    Path(backup).unlink(missing_ok=True)
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
            _forget(tmp)
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


def _process_alive(pid: int) -> bool | None:
    """Whether process ``pid`` of this machine runs; None when it cannot be told (Windows,
    where ``os.kill`` would end it)."""
    if os.name == "nt":
        return None
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    except OSError:
        return None
    return True


def remove_dead_temporaries(folder: PathLike) -> list[str]:
    """Remove every temporary in ``folder`` whose process is gone; their paths.

    A temporary's name carries the id of the process that made it and a hash of its host
    (:func:`_temp_name`); one made on this machine by a process that no longer runs (killed:
    SIGKILL, a crash, a power cut) is removed whatever its file's name or age, also the
    temporary of a temporary (``..g.<t1>.part.<t2>.part.laz``), a writer's sidecar of it and a
    staging folder of tiles (:func:`temp_folder`) with everything in it.
    Temporaries of running processes, of this process, of other hosts (a shared folder) and
    names without a process id are left alone (:func:`remove_stale_temporaries` removes
    those of a job's outputs by age). Errors are ignored.

    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> token = f"p{2**22 + 12345}h{_HOST}r"  # a process id beyond any pid_max
    >>> dead = f".g.{token}k3x9q1zz.part.laz"
    >>> inner = f".{dead[:-4]}.{token}q8m2a7bb.part.laz"  # written through the first
    >>> for name in (dead, inner, "notes.laz"):
    ...     _ = (folder / name).write_text("")
    >>> sorted(pathlib.Path(p).name for p in remove_dead_temporaries(folder)) == [inner, dead]
    True
    >>> sorted(p.name for p in folder.iterdir())
    ['notes.laz']
    """
    folder = str(folder) or "."
    try:
        names = sorted(os.listdir(folder))
    except OSError:
        return []
    removed = []
    alive: dict[int, bool | None] = {}
    for name in names:
        match = _ANY_TEMP.fullmatch(name)
        token = _TOKEN.fullmatch(match.group(2)) if match else None
        if match is None or token is None or token.group(2) != _HOST:
            continue
        pid = int(token.group(1))
        if pid == os.getpid():  # ours while this process knows it, else an earlier process's
            gone = os.path.abspath(os.path.join(folder, match.group(1))) not in _LIVE
        else:
            if pid not in alive:
                alive[pid] = _process_alive(pid)
            gone = alive[pid] is False
        if not gone:
            continue
        full = os.path.join(folder, name)
        try:
            if os.path.isdir(full) and not os.path.islink(full):  # a staging folder
                shutil.rmtree(full)
                removed.append(full)
            elif os.path.isfile(full):
                os.unlink(full)
                removed.append(full)
        except OSError:
            continue
    return removed
