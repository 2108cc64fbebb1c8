"""The observation list of the picking dock: the rows of the current image with their residual
length after a calibration; selecting a row selects the point.

A view on a model (:class:`ObservationModel`): showing the rows after a change costs the same
for ten rows or ten thousand (Qt asks the model only for the cells on screen), where a
widget with one item per cell made seven items per row at every click.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
from qgis.PyQt.QtCore import (
    QT_TRANSLATE_NOOP,
    QAbstractTableModel,
    QCoreApplication,
    QItemSelectionModel,
    QModelIndex,
    Qt,
    pyqtSignal,
)
from qgis.PyQt.QtWidgets import QAbstractItemView, QTableView

__all__ = ["ObservationModel", "ObservationTable"]

_COLUMNS = (  # header texts, translated when shown
    QT_TRANSLATE_NOOP("ObservationModel", "image"),
    QT_TRANSLATE_NOOP("ObservationModel", "point"),
    QT_TRANSLATE_NOOP("ObservationModel", "type"),
    QT_TRANSLATE_NOOP("ObservationModel", "target"),
    QT_TRANSLATE_NOOP("ObservationModel", "col"),
    QT_TRANSLATE_NOOP("ObservationModel", "row"),
    QT_TRANSLATE_NOOP("ObservationModel", "|v| px"),
)


class ObservationModel(QAbstractTableModel):
    """Rows ``rows[k]`` for k in ``indices`` (indices into the observation list), with the
    residual of k when it has one."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.rows: Sequence = ()
        self.indices: list[int] = []
        self.residuals: Mapping[int, np.ndarray] = {}

    def set_rows(
        self, rows: Sequence, indices: Sequence[int], residuals: Mapping[int, np.ndarray]
    ) -> None:
        self.beginResetModel()
        self.rows, self.indices, self.residuals = rows, list(indices), residuals
        self.endResetModel()

    def rowCount(self, parent=QModelIndex()) -> int:  # noqa: B008 - Qt override
        return 0 if parent.isValid() else len(self.indices)

    def columnCount(self, parent=QModelIndex()) -> int:  # noqa: B008 - Qt override
        return 0 if parent.isValid() else len(_COLUMNS)

    def text(self, r: int, c: int) -> str:
        """The text of a cell (row r of the table, column c)."""
        k = self.indices[r]
        if k >= len(self.rows):  # (a change not shown yet)
            return ""
        o = self.rows[k]
        if c == 4:
            return f"{o.col:.2f}"
        if c == 5:
            return f"{o.row:.2f}"
        if c == 6:
            v = self.residuals.get(k)
            return "" if v is None or not np.isfinite(v).all() else f"{math.hypot(*v):.2f}"
        return str((o.image_id, o.point_id, o.type, o.target_id)[c])

    def data(self, index, role=Qt.ItemDataRole.DisplayRole):
        if not index.isValid():
            return None
        if role == Qt.ItemDataRole.DisplayRole:
            return self.text(index.row(), index.column())
        if role == Qt.ItemDataRole.UserRole:
            return self.indices[index.row()]
        return None

    def headerData(self, section, orientation, role=Qt.ItemDataRole.DisplayRole):
        if role == Qt.ItemDataRole.DisplayRole and orientation == Qt.Orientation.Horizontal:
            return QCoreApplication.translate("ObservationModel", _COLUMNS[section])
        return super().headerData(section, orientation, role)


class ObservationTable(QTableView):
    """Read-only table of observation rows.

    Signals
    -------
    rowSelected(int)
        The user selected a row: its index in the observation list.
    """

    rowSelected = pyqtSignal(int)  # noqa: N815 - Qt signal naming

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.model_ = ObservationModel(self)
        self.setModel(self.model_)
        self.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        # no row numbers: the vertical header would ask the model for every row's label
        self.verticalHeader().hide()
        self.verticalHeader().setDefaultSectionSize(self.fontMetrics().height() + 6)
        self._filling = False
        self.selectionModel().selectionChanged.connect(self._selected)

    def fill(
        self,
        rows: Sequence,
        indices: Sequence[int],
        residuals: Mapping[int, np.ndarray],
        selected: int,
    ) -> None:
        """Show ``rows[k]`` for k in ``indices`` (with the residual of k, if any); select the
        row of index ``selected`` (without signalling)."""
        self._filling = True
        try:
            self.model_.set_rows(rows, indices, residuals)
            self.select(selected)
        finally:
            self._filling = False

    def select(self, k: int) -> None:
        """Select (and scroll to) the row of observation index ``k``; -1: none."""
        was, self._filling = self._filling, True
        try:
            sm = self.selectionModel()
            r = self.row_of(k)
            if r < 0:
                sm.clearSelection()
                return
            index = self.model_.index(r, 0)
            sm.select(
                index,
                QItemSelectionModel.SelectionFlag.ClearAndSelect
                | QItemSelectionModel.SelectionFlag.Rows,
            )
            self.scrollTo(index)
        finally:
            self._filling = was

    def row_of(self, k: int) -> int:
        """The table row showing observation index ``k`` (-1: not shown)."""
        try:
            return self.model_.indices.index(k)
        except ValueError:
            return -1

    def text(self, r: int, c: int) -> str:
        """The text of a cell (table row r, column c)."""
        return self.model_.text(r, c)

    def _selected(self, *_args) -> None:
        if self._filling:
            return
        rows = self.selectionModel().selectedRows()
        if rows:
            self.rowSelected.emit(int(self.model_.indices[rows[0].row()]))
