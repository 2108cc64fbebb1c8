"""QGIS Processing provider of the LiDAR Photogrammetry Toolkit: thin adapters around ``core``."""
