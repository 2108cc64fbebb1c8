"""The file endings each reader takes, apart from the readers (standard library only), so that a
job's spec can name them without importing numpy or the readers (``lidarphoto --help`` stays
light) and the input/output guard expands a folder with the same endings the job reads."""

from __future__ import annotations

#: Images read through GDAL/OpenCV (core/io/images.py).
IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".tif", ".tiff", ".bmp", ".jp2", ".img")
#: Terrestrial scans (core/io/scans.py).
SCAN_SUFFIXES = (".las", ".laz", ".ply", ".e57")
#: Control chips: GeoTIFFs (core/io/chips.py).
CHIP_SUFFIXES = (".tif", ".tiff")
#: Ground photos of control plates (core/io/control_chips.py).
PHOTO_SUFFIXES = (".tif", ".tiff", ".jpg", ".jpeg", ".png")
