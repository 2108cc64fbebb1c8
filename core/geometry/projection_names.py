"""The names of the central projections (:mod:`.projection` holds their formulas), in a module of
their own that imports no numerical library, so that the help lists them without numpy
(tests/core/test_startup.py)."""

from __future__ import annotations

#: The projections, by the name used in camera files (key ``"projection"``).
PROJECTIONS: tuple[str, ...] = (
    "perspective",
    "equidistant",
    "equisolid",
    "orthographic",
    "stereographic",
)
FISHEYE_PROJECTIONS: tuple[str, ...] = PROJECTIONS[1:]
