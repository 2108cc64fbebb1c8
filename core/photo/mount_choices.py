"""The names of the nominal camera mounts (:mod:`.mount` holds their rotations) and what each
means, in a module of their own that imports no numerical library, so that the command line's
help lists them without numpy (tests/core/test_startup.py)."""

from __future__ import annotations

#: The nominal mounts of :data:`.mount.MOUNT_PRESETS`, in its order, and ``custom`` (a
#: matrix given by the user).
MOUNT_CHOICES = (
    "image_top_forward",
    "image_right_forward",
    "image_bottom_forward",
    "image_left_forward",
    "custom",
)

#: What each nominal mount means, as the toolbox and the dock show it.
MOUNT_LABELS = {
    "image_top_forward": "image top towards the flight direction (nose)",
    "image_right_forward": "image right side towards the flight direction",
    "image_bottom_forward": "image bottom towards the flight direction",
    "image_left_forward": "image left side towards the flight direction",
    "custom": "custom matrix (MOUNT_MATRIX)",
}
