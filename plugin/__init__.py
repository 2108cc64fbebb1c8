"""QGIS GUI layer of the LiDAR Photogrammetry Toolkit: plugin class, actions, dependency check."""
