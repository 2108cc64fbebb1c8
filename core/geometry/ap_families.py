"""The names of the AP families (:mod:`.ap_models` holds their lens models), in a module of their
own that imports no numerical library, so that the bundle adjustment's options and its help read
them without numpy (tests/core/test_startup.py)."""

from __future__ import annotations

#: The AP families of the bundle adjustment: option name -> lens model name. ``none`` keeps
#: the camera's own lens model fixed; ``conrady_brown`` is the physical Brown-Conrady model.
AP_FAMILIES: dict[str, str] = {
    "none": "none",
    "lens_k1k2": "lens_k1k2",
    "bauer": "bauer",
    "jacobsen": "jacobsen",
    "ebner": "ebner",
    "brown": "brown",
    "conrady_brown": "brown_conrady",
}
