"""The dialog behind the missing-packages message: the whole pip command for the Python QGIS
runs (``core.dependencies``), a Copy button, and an Install button that runs pip in the task
manager and says what came of it (pip's own message when it fails)."""

from __future__ import annotations

import importlib
import subprocess
from collections.abc import Callable, Sequence

from qgis.core import QgsApplication, QgsTask
from qgis.PyQt.QtCore import QCoreApplication
from qgis.PyQt.QtWidgets import (
    QApplication,
    QDialog,
    QDialogButtonBox,
    QLabel,
    QPlainTextEdit,
    QProgressBar,
    QPushButton,
    QVBoxLayout,
)

from ..core.dependencies import missing_modules, pip_argv, pip_command, pip_requirements

#: Seconds pip may take before the install is given up (a slow mirror, a large wheel).
PIP_TIMEOUT_S = 1800


class PipTask(QgsTask):
    """``argv`` (a pip call) in a worker thread; ``done(task)`` in the GUI thread with
    :attr:`returncode` and :attr:`output` (pip's stdout and stderr)."""

    def __init__(self, argv: Sequence[str], done: Callable[[PipTask], None]) -> None:
        super().__init__(
            QCoreApplication.translate(
                "PipTask", "Installing Python packages for LiDAR Photogrammetry"
            )
        )
        self.argv, self.done = list(argv), done
        self.returncode: int | None = None
        self.output = ""

    def run(self) -> bool:  # a worker thread: no widget here
        try:
            run = subprocess.run(self.argv, capture_output=True, text=True, timeout=PIP_TIMEOUT_S)
        except (OSError, subprocess.SubprocessError) as exc:
            self.output = str(exc)
            return False
        self.returncode, self.output = run.returncode, (run.stdout + run.stderr).strip()
        return run.returncode == 0

    def finished(self, result: bool) -> None:  # the GUI thread
        self.done(self)


class DependencyDialog(QDialog):
    """Missing ``modules``: the command to copy, and Install."""

    def __init__(self, modules: Sequence[str], parent=None) -> None:
        super().__init__(parent)
        self.modules = list(modules)
        self.task: PipTask | None = None
        self.setWindowTitle(self.tr("LiDAR Photogrammetry: missing Python packages"))
        layout = QVBoxLayout(self)
        names = ", ".join(pip_requirements(self.modules))
        self.intro = QLabel(
            self.tr(
                "The algorithms need these Python packages in the Python QGIS "
                "runs: {names}. Install them with this command, or press "
                "Install."
            ).format(names=names),
            self,
        )
        self.intro.setWordWrap(True)
        self.command = QPlainTextEdit(pip_command(self.modules), self)
        self.command.setReadOnly(True)
        self.progress = QProgressBar(self)
        self.progress.setRange(0, 0)  # busy: pip reports no fraction
        self.progress.hide()
        self.status = QLabel("", self)
        self.status.setWordWrap(True)
        self.log = QPlainTextEdit(self)
        self.log.setReadOnly(True)
        self.log.hide()
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close, self)
        self.copy_button = QPushButton(self.tr("Copy command"), self)
        self.install_button = QPushButton(self.tr("Install"), self)
        buttons.addButton(self.copy_button, QDialogButtonBox.ButtonRole.ActionRole)
        buttons.addButton(self.install_button, QDialogButtonBox.ButtonRole.ActionRole)
        buttons.rejected.connect(self.reject)
        self.copy_button.clicked.connect(self.copy_command)
        self.install_button.clicked.connect(self.install)
        for w in (self.intro, self.command, self.progress, self.status, self.log, buttons):
            layout.addWidget(w)
        self.resize(720, 320)

    def copy_command(self) -> None:
        QApplication.clipboard().setText(self.command.toPlainText())
        self.status.setText(self.tr("The command is on the clipboard."))

    def install(self) -> None:
        """Run pip for QGIS's Python in the task manager (one run at a time)."""
        if self.task is not None:
            return
        self.install_button.setEnabled(False)
        self.progress.show()
        self.status.setText(self.tr("Installing..."))
        self.task = PipTask(pip_argv(self.modules), self._installed)
        QgsApplication.taskManager().addTask(self.task)

    def _installed(self, task: PipTask) -> None:
        self.task = None
        self.progress.hide()
        self.log.setPlainText(task.output)
        self.log.show()
        importlib.invalidate_caches()
        still = missing_modules(self.modules)
        if task.returncode == 0 and not still:
            self.status.setText(self.tr("Installed. The algorithms can run now."))
        elif task.returncode == 0:
            self.status.setText(
                self.tr(
                    "pip finished, but {names} still cannot be imported: restart "
                    "QGIS, or see pip's output below."
                ).format(names=", ".join(still))
            )
            self.install_button.setEnabled(True)
        else:
            self.status.setText(
                self.tr("pip failed (exit code {code}); its message is below.").format(
                    code=task.returncode
                )
            )
            self.install_button.setEnabled(True)
