"""The editable observation table of the picking dock, with undo/redo and autosave.

The rows and their undo history are the Qt-free
:class:`~lidarphoto.core.photo.picking_session.ObservationList`; every change (add, move,
delete, and their undo/redo) is followed at once by a save of the whole table to the
observation CSV of :mod:`core.io.observations`
(``image_id,point_id,col,row,sigma_px,type,target_id``), written atomically (temporary file in
the same folder, then ``os.replace``): the file on disk is always a complete table, whatever
happens to QGIS.

The session (paths of the camera, EO, observation and calibration files, images, layers and the
monoplotting DSM) is kept in the QGIS project (``QgsProject.writeEntry`` under the scope
``lidarphoto_picking``), so reopening the project restores it.
"""

from __future__ import annotations

import os
from pathlib import Path

from qgis.PyQt.QtCore import QObject, pyqtSignal

from ..core.errors import InputError
from ..core.io.observations import read_observations_csv, write_observations_csv
from ..core.photo.observation_list import Observation, ObservationList
from ..core.photo.observations import ImageObservations

__all__ = [
    "SESSION_KEYS",
    "SESSION_SCOPE",
    "Observation",
    "ObservationStore",
    "load_session",
    "save_session",
]

SESSION_SCOPE = "lidarphoto_picking"
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
    :class:`~lidarphoto.core.photo.picking_session.ObservationList`, :attr:`log`) and the
    autosaved CSV.

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
    ) -> None:
        super().__init__(parent)
        self.log = log if log is not None else ObservationList()
        self.path: Path | None = Path(path) if path else None
        self.save_count = 0
        self.last_error = ""

    @property
    def rows(self) -> list[Observation]:
        return self.log.rows

    # -- file ---------------------------------------------------------------------------------
    def load(self, path: str | os.PathLike) -> int:
        """Open an observation file (created empty if it does not exist); it becomes the
        autosave target. Returns the number of rows read.

        Raises
        ------
        InputError
            An unreadable table (names the file, row and column); the current rows and path are
            kept.
        """
        p = Path(path)
        rows: list[Observation] = []
        if p.is_file() and not _header_only(p):
            rows = ObservationList.rows_of(read_observations_csv(p))
        self.log.reset(rows)
        self.path = p
        if not p.exists():
            self.save()
        self.changed.emit()
        return len(rows)

    def save(self) -> bool:
        """Write the table atomically to :attr:`path`; False (and ``saveFailed``) on error."""
        if self.path is None:
            return False
        try:
            write_observations_csv(self.path, self.to_observations())
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
        self.log.move(index, col, row)
        self._changed()

    def delete(self, indices: int | list[int]) -> None:
        before = self.log.version
        self.log.delete(indices)
        if self.log.version != before:
            self._changed()

    def undo(self) -> None:
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
