"""At plugin load: tell the user, once, which of the core's packages are missing in QGIS's Python.

Nothing here raises: a missing package becomes one message-bar warning with a button to the
dialog that shows the whole ``pip`` command for the Python QGIS runs, copies it and installs
(plugin/dependency_dialog.py), plus a log entry with the command (``core.dependencies``).
"""

from __future__ import annotations

from collections.abc import Iterable

from qgis.core import Qgis, QgsMessageLog
from qgis.PyQt.QtCore import QCoreApplication

from ..core.dependencies import (
    OPTIONAL_MODULES,
    missing_message,
    missing_modules,
    optional_message,
    pip_requirements,
)

MESSAGE_TITLE = "LiDAR Photogrammetry"
LOG_TAG = "LiDAR Photogrammetry"


def report_missing(iface=None, modules: Iterable[str] | None = None) -> list[str]:
    """Check ``modules``; if any is missing, log it and push ONE message-bar warning.

    Missing optional accelerators (:data:`OPTIONAL_MODULES`) are only logged, as information.
    Returns the missing required import names. Never raises.
    """
    try:
        missing = missing_modules(modules)
        optional = missing_modules(OPTIONAL_MODULES) if modules is None else []
    except Exception:
        return []
    if optional:
        try:
            QgsMessageLog.logMessage(optional_message(optional), LOG_TAG, Qgis.MessageLevel.Info)
        except Exception:
            pass
    if not missing:
        return missing
    text = missing_message(missing)
    try:
        QgsMessageLog.logMessage(text, LOG_TAG, Qgis.MessageLevel.Warning)
        if iface is not None:
            push_missing(iface.messageBar(), missing, iface.mainWindow())
    except Exception:
        pass
    return missing


def push_missing(bar, missing: list[str], parent=None):
    """One warning in ``bar`` naming the packages, with a button to the install dialog (the
    whole command does not fit a message bar, and a bar's text cannot be copied)."""
    from qgis.PyQt.QtWidgets import QPushButton

    from .dependency_dialog import DependencyDialog

    names = ", ".join(pip_requirements(missing))
    item = bar.createMessage(
        MESSAGE_TITLE,
        QCoreApplication.translate("DependencyDialog", "Missing Python packages: {names}.").format(
            names=names
        ),
    )
    button = QPushButton(QCoreApplication.translate("DependencyDialog", "Install..."), item)
    item.layout().addWidget(button)

    def show() -> None:
        dialog = DependencyDialog(missing, parent)
        item.dialog = dialog  # kept alive with the message
        dialog.show()

    button.clicked.connect(show)
    item.button = button
    bar.pushWidget(item, Qgis.MessageLevel.Warning, 0)
    return item
