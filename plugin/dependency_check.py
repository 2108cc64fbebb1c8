"""At plugin load: tell the user, once, which of the core's packages are missing in QGIS's Python.

Nothing here raises: a missing package becomes one message-bar warning plus a log entry with
the exact ``pip`` command (``core.dependencies``).
"""

from __future__ import annotations

from collections.abc import Iterable

from qgis.core import Qgis, QgsMessageLog

from ..core.dependencies import (
    OPTIONAL_MODULES,
    missing_message,
    missing_modules,
    optional_message,
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
            iface.messageBar().pushMessage(MESSAGE_TITLE, text, Qgis.MessageLevel.Warning, 0)
    except Exception:
        pass
    return missing
