"""QGIS Processing provider of the LiDAR Photogrammetry Toolkit: thin adapters around ``core``.

The public API for the plugin's GUI (``plugin/`` imports only what is listed here):
:class:`LidarPhotoProvider` and the QGIS enums the GUI needs, resolved once for QGIS 3.22 to
4.x (:mod:`.compat`). The provider is imported on first use, so that importing the enums
does not load the algorithms.
"""

from __future__ import annotations

from typing import Any

from .compat import FIELD_DOUBLE, FIELD_INT, FIELD_STRING

__all__ = [
    "FIELD_DOUBLE",
    "FIELD_INT",
    "FIELD_STRING",
    "LidarPhotoProvider",
    "install_translator",
]


def __getattr__(name: str) -> Any:
    if name == "LidarPhotoProvider":
        from .provider import LidarPhotoProvider

        return LidarPhotoProvider
    if name == "install_translator":
        from .i18n import install_translator

        return install_translator
    raise AttributeError(name)
