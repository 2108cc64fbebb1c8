"""The observation list of the picking dock: the rows of the current image with their residual
length after a calibration; selecting a row selects the point."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
from qgis.PyQt.QtCore import Qt, pyqtSignal
from qgis.PyQt.QtWidgets import QAbstractItemView, QTableWidget, QTableWidgetItem

__all__ = ["ObservationTable"]

_COLUMNS = ("image", "point", "type", "target", "col", "row", "|v| px")


class ObservationTable(QTableWidget):
    """Read-only table of observation rows.

    Signals
    -------
    rowSelected(int)
        The user selected a row: its index in the observation list.
    """

    rowSelected = pyqtSignal(int)  # noqa: N815 - Qt signal naming

    def __init__(self, parent=None) -> None:
        super().__init__(0, len(_COLUMNS), parent)
        self.setHorizontalHeaderLabels([self.tr(t) for t in _COLUMNS])
        self.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.itemSelectionChanged.connect(self._selected)

    def fill(
        self,
        rows: Sequence,
        indices: Sequence[int],
        residuals: Mapping[int, np.ndarray],
        selected: int,
    ) -> None:
        """Show ``rows[k]`` for k in ``indices`` (with the residual of k, if any)."""
        self.blockSignals(True)
        self.setRowCount(len(indices))
        for r, k in enumerate(indices):
            o = rows[k]
            v = residuals.get(k)
            vals = (
                o.image_id,
                o.point_id,
                o.type,
                o.target_id,
                f"{o.col:.2f}",
                f"{o.row:.2f}",
                "" if v is None or not np.isfinite(v).all() else f"{math.hypot(*v):.2f}",
            )
            for c, text in enumerate(vals):
                item = QTableWidgetItem(text)
                item.setData(Qt.ItemDataRole.UserRole, k)
                self.setItem(r, c, item)
            if k == selected:
                self.selectRow(r)
        self.blockSignals(False)

    def _selected(self) -> None:
        items = self.selectedItems()
        if items:
            self.rowSelected.emit(int(items[0].data(Qt.ItemDataRole.UserRole)))
