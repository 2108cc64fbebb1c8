"""QGIS plugin entry point of the LiDAR Photogrammetry Toolkit (folder ``lidarphoto``)."""

from __future__ import annotations


def classFactory(iface):
    """Create the plugin; ``iface`` is None under qgis_process."""
    from .plugin.plugin import LidarPhotoPlugin

    return LidarPhotoPlugin(iface)
