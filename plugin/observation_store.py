"""The editable observation table of the picking dock, with undo/redo and autosave.

The rows, their undo history and the pending tie point are the Qt-free
:class:`~lidarphoto.core.photo.observation_list.ObservationList` of the dock's
:class:`~lidarphoto.core.photo.picking_session.PickingSession`; every change (add, move,
delete, and their undo/redo) is followed at once by a save of the whole table to the
observation CSV of :mod:`core.io.observations`
(``image_id,point_id,col,row,sigma_px,type,target_id``), written atomically by the core
(:mod:`core.io.atomic`: a temporary ``.<stem>.<random>.part.csv`` in the same folder, given the
file's mode, then ``os.replace``): the file on disk is always a complete table, whatever happens
to QGIS. Each row's line is formatted once and kept, so a save costs one write of the
table (about 1 ms for 3,000 rows) and not its formatting. Opening a file removes the
temporaries of it that a killed QGIS left behind.

The session (paths of the camera, EO, observation and calibration files, images, layers and the
monoplotting DSM) is kept in the QGIS project (``QgsProject.writeEntry`` under the scope
``lidarphoto_picking``), so reopening the project restores it.
"""

from __future__ import annotations

import contextlib
import csv
import gc
import io
import os
from collections.abc import Iterator
from pathlib import Path

from qgis.PyQt.QtCore import QObject, pyqtSignal

from ..core.errors import InputError
from ..core.io.atomic import atomic_write, remove_stale_temporaries
from ..core.io.observations import OBSERVATION_COLUMNS, observation_cells, read_observations_csv
from ..core.photo.observation_list import Observation, ObservationList
from ..core.photo.observations import ImageObservations

__all__ = [
    "SESSION_KEYS",
    "SESSION_SCOPE",
    "STALE_TEMPORARY_S",
    "Observation",
    "ObservationStore",
    "gc_deferred",
    "load_session",
    "save_session",
]

SESSION_SCOPE = "lidarphoto_picking"
#: a temporary of the observation file older than this is a leftover (a save takes
#: milliseconds; a younger one may be another QGIS saving the same file right now), seconds
STALE_TEMPORARY_S = 10.0
#: text entries of the session; "images" is a list
SESSION_KEYS = (
    "camera",
    "eo",
    "observations",
    "planes_layer",
    "lines_layer",
    "lcps_layer",
    "trajectory",
    "planes_csv",
    "lines_csv",
    "lcps_csv",
    "lever_arm",
    "mount",
    "boresight",
    "current_image",
    "dsm_layer",
    "dsm_file",
    "dsm_cell",
)


@contextlib.contextmanager
def gc_deferred() -> Iterator[None]:
    """Pause Python's cyclic garbage collector while a block makes many short-lived objects
    (reading a table, restoring the dock).

    Those objects die by reference counting either way; paused, the collections that would
    run meanwhile do not promote them to the oldest generation, whose growth is what brings a
    full collection (tens of ms with the GUI frozen; 40 ms in the benchmark's QGIS). The
    collector is restored on exit (left off if it was off).
    """
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def _csv_line(cells) -> str:
    """One CSV line as :func:`~lidarphoto.core.io.tables.write_csv_atomic` writes it."""
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow(cells)
    return buf.getvalue()


_HEADER = _csv_line(OBSERVATION_COLUMNS)


def _header_only(path: Path) -> bool:
    """True for an empty file or a table with a header and no rows (what an empty store
    writes; the core reader refuses it)."""
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError):
        return False  # the reader reports it
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    return len(lines) <= 1


class ObservationStore(QObject):
    """The observation rows with their undo history (a core
    :class:`~lidarphoto.core.photo.observation_list.ObservationList`, :attr:`log`) and the
    autosaved CSV. With a ``session``, its list is :attr:`log` and moves and deletions go
    through the session (they keep its pending tie point consistent).

    Signals
    -------
    changed()
        After every change (the file is already saved).
    saveFailed(str)
        The autosave could not write the file (the rows stay in memory, nothing is lost; the
        next change retries).
    """

    changed = pyqtSignal()
    saveFailed = pyqtSignal(str)  # noqa: N815 - Qt signal naming

    def __init__(
        self,
        path: str | os.PathLike | None = None,
        parent=None,
        log: ObservationList | None = None,
        session=None,
    ) -> None:
        super().__init__(parent)
        self.session = session
        if session is not None:
            log = session.observations
        self.log = log if log is not None else ObservationList()
        self.path: Path | None = Path(path) if path else None
        self.save_count = 0
        self.last_error = ""
        self.removed_temporaries: list[str] = []
        #: id(row) -> (row, its CSV line): rows are immutable, each is formatted once
        self._lines_of: dict[int, tuple[Observation, str]] = {}

    @property
    def rows(self) -> list[Observation]:
        return self.log.rows

    # -- file ---------------------------------------------------------------------------------
    def load(self, path: str | os.PathLike) -> int:
        """Open an observation file (created empty if it does not exist); it becomes the
        autosave target. Temporaries of it older than :data:`STALE_TEMPORARY_S` (left by a
        save that was killed) are removed first (:attr:`removed_temporaries`). Returns the
        number of rows read.

        Raises
        ------
        InputError
            An unreadable table (names the file, row and column); the current rows and path are
            kept.
        """
        p = Path(path)
        self.removed_temporaries = remove_stale_temporaries(p, STALE_TEMPORARY_S)
        rows: list[Observation] = []
        if p.is_file() and not _header_only(p):
            with gc_deferred():
                rows = ObservationList.rows_of(read_observations_csv(p))
        self.log.reset(rows)
        self._lines_of.clear()
        self.path = p
        if not p.exists():
            self.save()
        self.changed.emit()
        return len(rows)

    def _lines(self) -> list[str]:
        """The CSV line of every row, formatted once per row object (the cells of
        :func:`~lidarphoto.core.io.observations.observation_cells`, written by the same
        ``csv`` dialect as the core's writer: the file is the one it would write)."""
        cache = self._lines_of

        def line(o: Observation) -> str:
            text = _csv_line(
                observation_cells(
                    o.image_id, o.point_id, o.col, o.row, o.sigma_px, o.type, o.target_id
                )
            )
            cache[id(o)] = (o, text)
            return text

        # an id in the cache is that of the row object it holds (kept alive there), so a hit
        # is the same row: no identity test needed
        out = [hit[1] if (hit := cache.get(id(o))) else line(o) for o in self.log.rows]
        if len(cache) > 2 * len(out) + 64:  # rows deleted or moved since: forget them
            keep = {id(o) for o in self.log.rows}
            self._lines_of = {k: v for k, v in cache.items() if k in keep}
        return out

    def save(self) -> bool:
        """Write the table atomically to :attr:`path`; False (and ``saveFailed``) on error."""
        if self.path is None:
            return False
        try:
            text = "".join([_HEADER, *self._lines()])
            with atomic_write(self.path, newline="") as fh:
                fh.write(text)
        except (OSError, InputError) as exc:
            self.last_error = f"{self.path}: {exc}"
            self.saveFailed.emit(self.last_error)
            return False
        self.save_count += 1
        self.last_error = ""
        return True

    def _changed(self) -> None:
        self.save()
        self.changed.emit()

    def to_observations(self) -> ImageObservations:
        return self.log.to_observations()

    # -- edits (each one undoable, then saved) -----------------------------------------------
    def add(self, rows: Observation | list[Observation], text: str = "") -> int:
        """Append one or more rows as one undoable step; returns the index of the first."""
        at = self.log.add(rows, text)
        if at >= 0:
            self._changed()
        return at

    def move(self, index: int, col: float, row: float) -> None:
        if self.session is not None:
            self.session.move(index, col, row)
        else:
            self.log.move(index, col, row)
        self._changed()

    def delete(self, indices: int | list[int]) -> None:
        before = self.log.version
        if self.session is not None:
            self.session.delete(indices)
        else:
            self.log.delete(indices)
        if self.log.version != before:
            self._changed()

    def undo(self) -> None:
        """Undo the last edit (with the session's pending tie point as it was before it)."""
        if self.log.undo() is not None:
            self._changed()

    def redo(self) -> None:
        if self.log.redo() is not None:
            self._changed()

    def edited(self) -> None:
        """Save and signal after an edit made on :attr:`log` directly."""
        self._changed()

    # -- queries ------------------------------------------------------------------------------
    def indices_of_image(self, image_id: str) -> list[int]:
        return self.log.indices_of_image(image_id)

    def image_ids(self) -> set[str]:
        return self.log.image_ids()

    def next_point_id(self, prefix: str) -> str:
        """A point id ``<prefix><n>`` not used yet."""
        return self.log.next_point_id(prefix)


def save_session(project, values: dict) -> None:
    """Store the dock's session in a QgsProject (text entries; ``images`` as a list)."""
    for key in SESSION_KEYS:
        if key in values:
            project.writeEntry(SESSION_SCOPE, key, str(values[key] or ""))
    if "images" in values:
        project.writeEntry(SESSION_SCOPE, "images", [str(p) for p in values["images"]])
    project.setDirty(True)


def load_session(project) -> dict:
    """The session stored by :func:`save_session` (missing keys are absent)."""
    out: dict = {}
    for key in SESSION_KEYS:
        value, ok = project.readEntry(SESSION_SCOPE, key, "")
        if ok and value:
            out[key] = value
    images, ok = project.readListEntry(SESSION_SCOPE, "images", [])
    if ok and images:
        out["images"] = list(images)
    return out
