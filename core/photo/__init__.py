"""Photogrammetry: mount and direct georeferencing, exterior orientation, resection,
boresight calibration, monoplotting and the picking geometry."""
