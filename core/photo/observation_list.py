"""The rows of an observation table being edited: add, move and delete with an undo and redo
history (what the picking dock's Qt store wraps).

Besides the rows, the list carries one *attached* value that belongs with them (the picking
session keeps its pending tie point there): every edit records the value before and after it,
so undo and redo put it back together with the rows."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple, Union

import numpy as np
from numpy.typing import NDArray

from .observations import DEFAULT_SIGMA_PX, ImageObservations

Array = NDArray[np.float64]


# ----------------------------------------------------------------------------- observations
class Observation(NamedTuple):
    """One row of the observation table (:mod:`core.io.observations`): an image point in
    pixels (col, row) and what it measures.

    Immutable. A named tuple of text and numbers: a table of thousands of rows costs the
    garbage collector nothing (such tuples are not tracked), where each instance of a class
    is tracked, and a picking dock that reads one would make Python's full collections (tens
    of ms, the GUI frozen) come sooner.
    """

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


class _Keep:
    """The default of ``attached`` in the edits: the attached value stays as it is."""

    def __repr__(self) -> str:
        return "KEEP"


#: ``attached=KEEP`` (the default of every edit): the attached value does not change
KEEP: Any = _Keep()


@dataclass(frozen=True)
class Step:
    """One entry of the history: an edit and the attached value before and after it."""

    edit: Edit
    before: Any = None
    after: Any = None


class ObservationList:
    """The observation rows and the history of their edits (undo, redo).

    Every change is an edit object with ``apply`` and ``revert``; :meth:`push` applies one and
    records it (a new edit drops what was undone). :attr:`version` grows with every change.

    :attr:`attached` is a value the owner keeps with the rows (None by default; the picking
    session's pending tie point): an edit given ``attached=`` sets it, and the history records
    it before and after each edit, so :meth:`undo` and :meth:`redo` restore it with the rows.
    Treat it as immutable (replace it, never change it in place): the history keeps references.

    >>> log = ObservationList()
    >>> log.add(Observation("a", "T1", 10.5, 20.5, "tie", "3"), attached="T1 pending")
    0
    >>> log.attached
    'T1 pending'
    >>> log.undo().text, log.rows, log.attached
    ('add T1', [], None)
    >>> _ = log.redo(); len(log.rows), log.attached
    (1, 'T1 pending')
    """

    def __init__(self, rows: Iterable[Observation] = ()) -> None:
        self.rows: list[Observation] = list(rows)
        self.attached: Any = None
        self._by_image: tuple[int, list[Observation], dict[str, list[int]]] | None = None
        self._pixels: tuple | None = None
        self._done: list[Step] = []
        self._undone: list[Step] = []
        self.version = 0

    def reset(self, rows: Iterable[Observation] = ()) -> None:
        """Replace every row (a file opened); the history and the attached value are cleared."""
        self.rows = list(rows)
        self.attached = None
        self._by_image = None
        self._done.clear()
        self._undone.clear()
        self.version += 1

    # -- edits --------------------------------------------------------------------------------
    def push(self, edit: Edit, attached: Any = KEEP) -> None:
        """Apply an edit and record it for undo; ``attached`` (unless KEEP) becomes the
        attached value."""
        before = self.attached
        edit.apply(self.rows)
        if attached is not KEEP:
            self.attached = attached
        self._done.append(Step(edit, before, self.attached))
        self._undone.clear()
        self._changed(edit, forward=True)

    def _changed(self, edit: Edit, forward: bool) -> None:
        """A new version; the index of the rows by image follows an add at the end, its undo
        and a move at once (the common edits of picking), else it is rebuilt when asked."""
        cache = self._by_image
        self.version += 1
        if cache is None or cache[0] != self.version - 1 or cache[1] is not self.rows:
            self._by_image = None
            return
        by_image = cache[2]
        n = len(self.rows)
        if isinstance(edit, AddRows) and forward and edit.at + len(edit.rows) == n:
            for j, o in enumerate(edit.rows):
                by_image.setdefault(o.image_id, []).append(edit.at + j)
        elif isinstance(edit, AddRows) and not forward and edit.at == n:
            for o in reversed(edit.rows):  # the largest indices: the last of their image
                by_image[o.image_id].pop()
        elif not isinstance(edit, MoveRow):  # (a move keeps the image)
            self._by_image = None
            return
        self._by_image = (self.version, self.rows, by_image)

    def add(
        self, rows: Observation | Sequence[Observation], text: str = "", attached: Any = KEEP
    ) -> int:
        """Append one or more rows as one edit; the index of the first (-1: none given)."""
        batch = (rows,) if isinstance(rows, Observation) else tuple(rows)
        if not batch:
            return -1
        at = len(self.rows)
        self.push(AddRows(at, batch, text or f"add {batch[0].point_id}"), attached)
        return at

    def move(self, index: int, col: float, row: float, attached: Any = KEEP) -> None:
        """Move the point of row ``index`` to (col, row)."""
        before = self.rows[index]
        after = before._replace(col=float(col), row=float(row))
        self.push(MoveRow(index, before, after, f"move {before.point_id}"), attached)

    def delete(self, indices: int | Iterable[int], attached: Any = KEEP) -> None:
        """Delete rows (one edit)."""
        idx = sorted({indices} if isinstance(indices, int) else set(indices))
        if idx:
            removed = tuple((i, self.rows[i]) for i in idx)
            self.push(DeleteRows(removed, f"delete {len(idx)} point(s)"), attached)

    @property
    def can_undo(self) -> bool:
        return bool(self._done)

    @property
    def can_redo(self) -> bool:
        return bool(self._undone)

    def undo(self) -> Edit | None:
        """Revert the last edit (the attached value goes back to what it was before it);
        None when there is none."""
        if not self._done:
            return None
        step = self._done.pop()
        step.edit.revert(self.rows)
        self.attached = step.before
        self._undone.append(step)
        self._changed(step.edit, forward=False)
        return step.edit

    def redo(self) -> Edit | None:
        """Apply again the last undone edit (and its attached value); None when there is
        none."""
        if not self._undone:
            return None
        step = self._undone.pop()
        step.edit.apply(self.rows)
        self.attached = step.after
        self._done.append(step)
        self._changed(step.edit, forward=True)
        return step.edit

    # -- queries ------------------------------------------------------------------------------
    def indices_of_image(self, image_id: str) -> list[int]:
        """Row indices of one image, ascending (an index kept up to date, see
        :meth:`_changed`)."""
        cache = self._by_image
        if cache is None or cache[0] != self.version or cache[1] is not self.rows:
            by_image: dict[str, list[int]] = {}
            for k, o in enumerate(self.rows):
                by_image.setdefault(o.image_id, []).append(k)
            cache = self._by_image = (self.version, self.rows, by_image)
        return list(cache[2].get(image_id, ()))

    def image_ids(self) -> set[str]:
        return {o.image_id for o in self.rows}

    def pixels(self, indices: Sequence[int]) -> Array:
        """(N, 2) pixels of the given rows."""
        return np.array([[self.rows[k].col, self.rows[k].row] for k in indices]).reshape(-1, 2)

    def pixels_of_image(self, image_id: str) -> tuple[list[int], Array]:
        """The rows of one image and their (N, 2) pixels (kept until the next change: the
        hit test of every mouse press asks for them)."""
        cache = self._pixels
        if cache is None or cache[:2] != (self.version, image_id) or cache[2] is not self.rows:
            rows = self.indices_of_image(image_id)
            px = self.pixels(rows)
            px.flags.writeable = False  # shared by the callers until the next change
            cache = self._pixels = (self.version, image_id, self.rows, rows, px)
        return list(cache[3]), cache[4]

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
