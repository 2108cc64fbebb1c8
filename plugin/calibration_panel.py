"""The Calibration tab of the picking dock: the calibration inputs that are not in the Project
tab, the Run button and the result (boresight per group, residual RMS)."""

from __future__ import annotations

import math

from qgis.gui import QgsFileWidget
from qgis.PyQt.QtCore import Qt, pyqtSignal
from qgis.PyQt.QtWidgets import QComboBox, QFormLayout, QLabel, QLineEdit, QPushButton, QWidget

from ..core.photo.mount import MOUNT_CHOICES

__all__ = ["AUTO_CALIBRATION_ALG", "CALIBRATION_ALG", "CalibrationPanel"]

#: the algorithm (core job) the Run button runs
CALIBRATION_ALG = "lidarphoto:boresightcalibration"
#: the algorithm of the *Calibrate automatically* button
AUTO_CALIBRATION_ALG = "lidarphoto:autoboresight"
_TABLE_KEYS = ("planes_csv", "lines_csv", "lcps_csv")


class CalibrationPanel(QWidget):
    """Trajectory, lever arm, mount, initial boresight, the plane/line/LCP tables (their rows
    replace the layers' objects of the same id: full covariances), Run, result.

    Signals
    -------
    settingsChanged()
        A setting was edited (the session is saved).
    tablesChanged()
        A plane, line or LCP table was chosen (the control is read again).
    """

    settingsChanged = pyqtSignal()  # noqa: N815 - Qt signal naming
    tablesChanged = pyqtSignal()  # noqa: N815

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        form = QFormLayout(self)
        self.trajectory_edit = QgsFileWidget()
        self.trajectory_edit.setFilter(self.tr("Trajectory CSV (*.csv *.txt)"))
        self.lever_edit = QLineEdit("0,0,0")
        self.mount_combo = QComboBox()
        self.mount_combo.addItems(list(MOUNT_CHOICES[:-1]))
        self.boresight_edit = QLineEdit("0,0,0")
        self.planes_csv_edit = QgsFileWidget()
        self.lines_csv_edit = QgsFileWidget()
        self.lcps_csv_edit = QgsFileWidget()
        for w in self.table_edits():
            w.setFilter(self.tr("CSV (*.csv)"))
            w.setToolTip(
                self.tr(
                    "Optional: its rows replace the layer's features of the same id (with "
                    "their full covariance) in the overlays and the calibration"
                )
            )
        self.run_button = QPushButton(self.tr("Run boresight calibration"))
        self.run_button.setObjectName("lidarphotoRunCalibration")
        self.run_button.setToolTip(
            self.tr("Runs {} in the background with the current observations").format(
                CALIBRATION_ALG
            )
        )
        self.auto_button = QPushButton(self.tr("Calibrate automatically"))
        self.auto_button.setObjectName("lidarphotoRunAutoCalibration")
        self.auto_button.setToolTip(
            self.tr(
                "Runs {} in the background on the open images: no picked observation needed "
                "(image edges along the LiDAR lines of the line layer or table)"
            ).format(AUTO_CALIBRATION_ALG)
        )
        self.use_eo_button = QPushButton(self.tr("Show with the calibrated orientation"))
        self.use_eo_button.setObjectName("lidarphotoUseCalibratedEo")
        self.use_eo_button.setToolTip(
            self.tr(
                "Overlays, predictions and monoplotting with the exterior orientation of the "
                "last calibration (its file, eo_calibrated.csv, becomes the Project tab's)"
            )
        )
        self.use_eo_button.setEnabled(False)
        self.result_label = QLabel()
        self.result_label.setWordWrap(True)
        self.result_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        form.addRow(self.tr("Trajectory"), self.trajectory_edit)
        form.addRow(self.tr("Lever arm x,y,z (m)"), self.lever_edit)
        form.addRow(self.tr("Mount"), self.mount_combo)
        form.addRow(self.tr("Initial boresight (deg)"), self.boresight_edit)
        form.addRow(self.tr("Plane table"), self.planes_csv_edit)
        form.addRow(self.tr("Line table"), self.lines_csv_edit)
        form.addRow(self.tr("LCP table"), self.lcps_csv_edit)
        form.addRow(self.run_button)
        form.addRow(self.auto_button)
        form.addRow(self.result_label)
        form.addRow(self.use_eo_button)

        self.trajectory_edit.fileChanged.connect(lambda *_: self.settingsChanged.emit())
        for w in self.table_edits():
            w.fileChanged.connect(lambda *_: self.tablesChanged.emit())
        for w in (self.lever_edit, self.boresight_edit):
            w.editingFinished.connect(self.settingsChanged.emit)
        self.mount_combo.currentIndexChanged.connect(lambda *_: self.settingsChanged.emit())

    def table_edits(self) -> tuple[QgsFileWidget, QgsFileWidget, QgsFileWidget]:
        return self.planes_csv_edit, self.lines_csv_edit, self.lcps_csv_edit

    def table_paths(self) -> tuple[str, str, str]:
        return tuple(w.filePath() for w in self.table_edits())  # type: ignore[return-value]

    # -- session ------------------------------------------------------------------------------
    def values(self) -> dict:
        out = {
            "trajectory": self.trajectory_edit.filePath(),
            "lever_arm": self.lever_edit.text(),
            "mount": self.mount_combo.currentText(),
            "boresight": self.boresight_edit.text(),
        }
        out.update(zip(_TABLE_KEYS, self.table_paths()))
        return out

    def restore(self, s: dict) -> None:
        """Set the widgets from a stored session (call with the panel's signals blocked)."""
        self.trajectory_edit.setFilePath(s.get("trajectory", ""))
        for key, w in zip(_TABLE_KEYS, self.table_edits()):
            w.setFilePath(s.get(key, ""))
        self.lever_edit.setText(s.get("lever_arm", "0,0,0"))
        self.boresight_edit.setText(s.get("boresight", "0,0,0"))
        if s.get("mount"):
            self.mount_combo.setCurrentText(s["mount"])

    # -- running and result -------------------------------------------------------------------
    def set_running(self, running: bool) -> None:
        self.run_button.setEnabled(not running)
        self.auto_button.setEnabled(not running)
        self.use_eo_button.setEnabled(False)
        if running:
            self.result_label.setText(self.tr("Calibration running…"))

    def show_result(self, groups, stats: tuple[int, float, float]) -> str:
        """Show the boresight of each group ((group, arc-seconds (3,), sigma0)) and the
        residual statistics (count, RMS, max in pixels); returns the text."""
        lines = [
            f'{g}: dω {a[0]:.1f}" dφ {a[1]:.1f}" dκ {a[2]:.1f}" (σ0 {sigma0:.2f})'
            for g, a, sigma0 in groups
        ]
        n, rms, vmax = stats
        if n and math.isfinite(rms):
            lines.append(self.tr("{} residuals: RMS {:.2f} px, max {:.2f} px").format(n, rms, vmax))
        text = "\n".join(lines)
        self.result_label.setText(text)
        return text
