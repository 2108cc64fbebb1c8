"""COLMAP's camera models, the block imports' default pixel size and the Metashape import's
image-name choices, in a module that imports no numerical library (the help lists them
without numpy: tests/core/test_startup.py)."""

from __future__ import annotations

from typing import Dict, Tuple

#: Pixel size given to an imported COLMAP camera when none is stated, mm (COLMAP stores none;
#: it scales the millimetres of the camera, never its projection).
DEFAULT_PIXEL_SIZE_MM = 0.004

#: How the Metashape import names the images in the EO: ``label`` (the camera's label as
#: Metashape shows it) or ``file`` (the label's file name without folder and extension: how
#: orthorectify and the picking dock match image files).
METASHAPE_IMAGE_NAMES = ("label", "file")

#: COLMAP's camera models: id -> (name, parameter names), as in its format documentation.
COLMAP_MODELS: Dict[int, Tuple[str, Tuple[str, ...]]] = {
    0: ("SIMPLE_PINHOLE", ("f", "cx", "cy")),
    1: ("PINHOLE", ("fx", "fy", "cx", "cy")),
    2: ("SIMPLE_RADIAL", ("f", "cx", "cy", "k")),
    3: ("RADIAL", ("f", "cx", "cy", "k1", "k2")),
    4: ("OPENCV", ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2")),
    5: ("OPENCV_FISHEYE", ("fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4")),
    6: ("FULL_OPENCV", ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6")),
    7: ("FOV", ("fx", "fy", "cx", "cy", "omega")),
    8: ("SIMPLE_RADIAL_FISHEYE", ("f", "cx", "cy", "k")),
    9: ("RADIAL_FISHEYE", ("f", "cx", "cy", "k1", "k2")),
    10: (
        "THIN_PRISM_FISHEYE",
        ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "sx1", "sy1"),
    ),
    11: (
        "RAD_TAN_THIN_PRISM_FISHEYE",
        (
            "fx",
            "fy",
            "cx",
            "cy",
            "k0",
            "k1",
            "k2",
            "k3",
            "k4",
            "k5",
            "p0",
            "p1",
            "s0",
            "s1",
            "s2",
            "s3",
        ),
    ),
}

#: Where the Pix4D import puts the centre of the top-left pixel in Pix4D's K: ``corner``
#: (the pixel coordinates start at the image's top-left corner, the first pixel's centre at
#: (0.5, 0.5): the project's convention) or ``centre`` (the first pixel's centre at (0, 0),
#: OpenCV's). Pix4D's documentation found does not state it (docs/formats.md, Pix4D).
PIX4D_PIXEL_ORIGINS = ("corner", "centre")
