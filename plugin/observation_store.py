"""The editable observation table of the picking dock, with undo/redo and autosave.

Every change (add, move, delete, and their undo/redo) goes through a ``QUndoStack`` and is
followed at once by a save of the whole table to the observation CSV of
:mod:`core.io.observations` (``image_id,point_id,col,row,sigma_px,type,target_id``), written
atomically (temporary file in the same folder, then ``os.replace``): the file on disk is always
a complete table, whatever happens to QGIS.

The session (paths of the camera, EO, observation and calibration files, images, layers and the
monoplotting DSM) is
kept in the QGIS project (``QgsProject.writeEntry`` under the scope ``lidarphoto_picking``), so
reopening the project restores it.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from qgis.PyQt.QtCore import QObject, pyqtSignal
from qgis.PyQt.QtWidgets import QUndoCommand, QUndoStack

from ..core.errors import InputError
from ..core.io.observations import read_observations_csv, write_observations_csv
from ..core.photo.observations import DEFAULT_SIGMA_PX, ImageObservations

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


@dataclass(frozen=True)
class Observation:
    """One row of the observation table (see :mod:`core.io.observations`)."""

    image_id: str
    point_id: str
    col: float
    row: float
    type: str
    target_id: str
    sigma_px: float = DEFAULT_SIGMA_PX


def _header_only(path: Path) -> bool:
    """True for an empty file or a table with a header and no rows (what an empty store
    writes; the core reader refuses it)."""
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError):
        return False  # the reader reports it
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    return len(lines) <= 1


class _Add(QUndoCommand):
    def __init__(self, store, rows: list[Observation], text: str) -> None:
        super().__init__(text)
        self.store, self.rows, self.at = store, rows, len(store.rows)

    def redo(self) -> None:
        self.store.rows[self.at : self.at] = self.rows
        self.store._changed()

    def undo(self) -> None:
        del self.store.rows[self.at : self.at + len(self.rows)]
        self.store._changed()


class _Move(QUndoCommand):
    def __init__(self, store, index: int, col: float, row: float) -> None:
        super().__init__(f"move {store.rows[index].point_id}")
        self.store, self.index = store, index
        self.before = store.rows[index]
        self.after = replace(self.before, col=float(col), row=float(row))

    def redo(self) -> None:
        self.store.rows[self.index] = self.after
        self.store._changed()

    def undo(self) -> None:
        self.store.rows[self.index] = self.before
        self.store._changed()


class _Delete(QUndoCommand):
    def __init__(self, store, indices: list[int]) -> None:
        super().__init__(f"delete {len(indices)} point(s)")
        self.store = store
        self.removed = [(i, store.rows[i]) for i in sorted(set(indices))]

    def redo(self) -> None:
        for i, _ in reversed(self.removed):
            del self.store.rows[i]
        self.store._changed()

    def undo(self) -> None:
        for i, row in self.removed:
            self.store.rows.insert(i, row)
        self.store._changed()


class ObservationStore(QObject):
    """The observation rows, an undo stack and the autosaved CSV.

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

    def __init__(self, path: str | os.PathLike | None = None, parent=None) -> None:
        super().__init__(parent)
        self.rows: list[Observation] = []
        self.undo_stack = QUndoStack(self)
        self.path: Path | None = Path(path) if path else None
        self.save_count = 0
        self.last_error = ""

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
            obs = read_observations_csv(p)
            rows = [
                Observation(i, pt, float(c), float(r), t, g, float(s))
                for i, pt, (c, r), s, t, g in zip(
                    obs.image_id, obs.point_id, obs.pixels, obs.sigma_px, obs.type, obs.target_id
                )
            ]
        self.rows = rows
        self.path = p
        self.undo_stack.clear()
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
        r = self.rows
        return ImageObservations.from_arrays(
            [o.image_id for o in r],
            [o.point_id for o in r],
            np.array([[o.col, o.row] for o in r], dtype=np.float64).reshape(-1, 2),
            np.array([o.sigma_px for o in r], dtype=np.float64),
            [o.type for o in r],
            [o.target_id for o in r],
        )

    # -- edits --------------------------------------------------------------------------------
    def add(self, rows: Observation | list[Observation], text: str = "") -> int:
        """Append one or more rows as one undoable step; returns the index of the first."""
        batch = [rows] if isinstance(rows, Observation) else list(rows)
        if not batch:
            return -1
        at = len(self.rows)
        self.undo_stack.push(_Add(self, batch, text or f"add {batch[0].point_id}"))
        return at

    def move(self, index: int, col: float, row: float) -> None:
        self.undo_stack.push(_Move(self, index, col, row))

    def delete(self, indices: int | list[int]) -> None:
        idx = [indices] if isinstance(indices, int) else list(indices)
        if idx:
            self.undo_stack.push(_Delete(self, idx))

    def undo(self) -> None:
        self.undo_stack.undo()

    def redo(self) -> None:
        self.undo_stack.redo()

    # -- queries ------------------------------------------------------------------------------
    def indices_of_image(self, image_id: str) -> list[int]:
        return [k for k, o in enumerate(self.rows) if o.image_id == image_id]

    def image_ids(self) -> set[str]:
        return {o.image_id for o in self.rows}

    def next_point_id(self, prefix: str) -> str:
        """A point id ``<prefix><n>`` not used yet."""
        used = {o.point_id for o in self.rows}
        n = len(self.rows) + 1
        while f"{prefix}{n}" in used:
            n += 1
        return f"{prefix}{n}"


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
