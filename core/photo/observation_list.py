"""The rows of an observation table being edited: add, move and delete with an undo and redo
history (what the picking dock's Qt store wraps)."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from typing import Union

import numpy as np
from numpy.typing import NDArray

from .observations import DEFAULT_SIGMA_PX, ImageObservations

Array = NDArray[np.float64]


# ----------------------------------------------------------------------------- observations
@dataclass(frozen=True)
class Observation:
    """One row of the observation table (:mod:`core.io.observations`): an image point in
    pixels (col, row) and what it measures."""

    image_id: str
    point_id: str
    col: float
    row: float
    type: str
    target_id: str
    sigma_px: float = DEFAULT_SIGMA_PX


@dataclass(frozen=True)
class AddRows:
    """Insert ``rows`` at index ``at``."""

    at: int
    rows: tuple[Observation, ...]
    text: str = ""

    def apply(self, rows: list[Observation]) -> None:
        rows[self.at : self.at] = self.rows

    def revert(self, rows: list[Observation]) -> None:
        del rows[self.at : self.at + len(self.rows)]


@dataclass(frozen=True)
class MoveRow:
    """Replace the row at ``index`` (``before``) by ``after`` (the same point, moved)."""

    index: int
    before: Observation
    after: Observation
    text: str = ""

    def apply(self, rows: list[Observation]) -> None:
        rows[self.index] = self.after

    def revert(self, rows: list[Observation]) -> None:
        rows[self.index] = self.before


@dataclass(frozen=True)
class DeleteRows:
    """Remove the rows ``removed`` ((index, row) pairs, ascending indices)."""

    removed: tuple[tuple[int, Observation], ...]
    text: str = ""

    def apply(self, rows: list[Observation]) -> None:
        for i, _ in reversed(self.removed):
            del rows[i]

    def revert(self, rows: list[Observation]) -> None:
        for i, row in self.removed:
            rows.insert(i, row)


Edit = Union[AddRows, MoveRow, DeleteRows]


class ObservationList:
    """The observation rows and the history of their edits (undo, redo).

    Every change is an edit object with ``apply`` and ``revert``; :meth:`push` applies one and
    records it (a new edit drops what was undone). :attr:`version` grows with every change.
    """

    def __init__(self, rows: Iterable[Observation] = ()) -> None:
        self.rows: list[Observation] = list(rows)
        self._done: list[Edit] = []
        self._undone: list[Edit] = []
        self.version = 0

    def reset(self, rows: Iterable[Observation] = ()) -> None:
        """Replace every row (a file opened); the history is cleared."""
        self.rows = list(rows)
        self._done.clear()
        self._undone.clear()
        self.version += 1

    # -- edits --------------------------------------------------------------------------------
    def push(self, edit: Edit) -> None:
        """Apply an edit and record it for undo."""
        edit.apply(self.rows)
        self._done.append(edit)
        self._undone.clear()
        self.version += 1

    def add(self, rows: Observation | Sequence[Observation], text: str = "") -> int:
        """Append one or more rows as one edit; the index of the first (-1: none given)."""
        batch = (rows,) if isinstance(rows, Observation) else tuple(rows)
        if not batch:
            return -1
        at = len(self.rows)
        self.push(AddRows(at, batch, text or f"add {batch[0].point_id}"))
        return at

    def move(self, index: int, col: float, row: float) -> None:
        """Move the point of row ``index`` to (col, row)."""
        before = self.rows[index]
        after = replace(before, col=float(col), row=float(row))
        self.push(MoveRow(index, before, after, f"move {before.point_id}"))

    def delete(self, indices: int | Iterable[int]) -> None:
        """Delete rows (one edit)."""
        idx = sorted({indices} if isinstance(indices, int) else set(indices))
        if idx:
            removed = tuple((i, self.rows[i]) for i in idx)
            self.push(DeleteRows(removed, f"delete {len(idx)} point(s)"))

    @property
    def can_undo(self) -> bool:
        return bool(self._done)

    @property
    def can_redo(self) -> bool:
        return bool(self._undone)

    def undo(self) -> Edit | None:
        """Revert the last edit; None when there is none."""
        if not self._done:
            return None
        edit = self._done.pop()
        edit.revert(self.rows)
        self._undone.append(edit)
        self.version += 1
        return edit

    def redo(self) -> Edit | None:
        """Apply again the last undone edit; None when there is none."""
        if not self._undone:
            return None
        edit = self._undone.pop()
        edit.apply(self.rows)
        self._done.append(edit)
        self.version += 1
        return edit

    # -- queries ------------------------------------------------------------------------------
    def indices_of_image(self, image_id: str) -> list[int]:
        return [k for k, o in enumerate(self.rows) if o.image_id == image_id]

    def image_ids(self) -> set[str]:
        return {o.image_id for o in self.rows}

    def pixels(self, indices: Sequence[int]) -> Array:
        """(N, 2) pixels of the given rows."""
        return np.array([[self.rows[k].col, self.rows[k].row] for k in indices]).reshape(-1, 2)

    def next_point_id(self, prefix: str) -> str:
        """A point id ``<prefix><n>`` not used yet."""
        used = {o.point_id for o in self.rows}
        n = len(self.rows) + 1
        while f"{prefix}{n}" in used:
            n += 1
        return f"{prefix}{n}"

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

    @staticmethod
    def rows_of(obs: ImageObservations) -> list[Observation]:
        """The rows of an observation table, in its order."""
        return [
            Observation(i, p, float(c), float(r), t, g, float(s))
            for i, p, (c, r), s, t, g in zip(
                obs.image_id, obs.point_id, obs.pixels, obs.sigma_px, obs.type, obs.target_id
            )
        ]
