"""How the camera is mounted on the INS: lever arm, nominal mount and boresight misalignment.

``R_c^b = R_nominal dR(d_omega, d_phi, d_kappa)`` (docs/conventions.md): the nominal mount is
one of :data:`MOUNT_PRESETS` or a custom rotation matrix; the boresight is the small
misalignment about the camera axes x, y, z.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.rotations import boresight_matrix, is_rotation
from .mount_choices import MOUNT_CHOICES, MOUNT_LABELS  # noqa: F401 - MOUNT_LABELS: the old address

Array = NDArray[np.float64]

# Nominal camera mounts R_c^b: columns are the camera axes x_c, y_c, z_c in the body frame
# (x forward, y right, z down). The camera looks along -z_c, i.e. straight down (+z_b) for all.
MOUNT_PRESETS: dict[str, Array] = {
    # image top (+y_c) points forward, image right (+x_c) points to the right wing
    "image_top_forward": np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]),
    # image right (+x_c) points forward, image top (+y_c) points to the left wing
    "image_right_forward": np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]),
    # image bottom (-y_c) points forward
    "image_bottom_forward": np.array([[0.0, -1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]),
    # image left (-x_c) points forward
    "image_left_forward": np.array([[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]),
}

if (*MOUNT_PRESETS, "custom") != MOUNT_CHOICES:  # the names the help lists without numpy
    raise ImportError("photo/mount_choices.py MOUNT_CHOICES differs from MOUNT_PRESETS")


@dataclass(frozen=True)
class Mount:
    """Camera mounting: lever arm (body frame, metres) and camera-to-body rotation.

    boresight: (d_omega, d_phi, d_kappa) in radians about the camera axes.
    """

    lever_arm: Array
    nominal: Array
    boresight: Array

    def __post_init__(self) -> None:
        for name, shape in (("lever_arm", (3,)), ("nominal", (3, 3)), ("boresight", (3,))):
            value = getattr(self, name)
            arr = np.asarray(value, dtype=np.float64)
            if arr.shape != shape or not np.all(np.isfinite(arr)):
                raise InputError(f"mount {name} must be {shape} finite numbers, got {value!r}")
            object.__setattr__(self, name, arr)
        if not is_rotation(self.nominal, atol=1e-6):
            raise InputError(
                "the custom mount matrix is not a rotation (orthonormal, determinant +1): "
                f"{np.round(self.nominal, 6).tolist()}"
            )

    @property
    def camera_to_body(self) -> Array:
        """``R_c^b = R_nominal dR``."""
        return self.nominal @ boresight_matrix(*self.boresight)

    @classmethod
    def from_parameters(
        cls,
        lever_arm: Sequence[float] = (0.0, 0.0, 0.0),
        mount: str = "image_top_forward",
        mount_matrix: Sequence[float] | None = None,
        boresight_deg: Sequence[float] = (0.0, 0.0, 0.0),
    ) -> Mount:
        """Build from the algorithms' parameters: lever arm (m), a preset name of
        :data:`MOUNT_CHOICES` (``custom`` takes the 9 numbers of ``mount_matrix``, row-major
        R_c^b) and the boresight in degrees."""
        if mount == "custom":
            if mount_matrix is None or len(mount_matrix) != 9:
                raise InputError("MOUNT custom needs MOUNT_MATRIX: 9 numbers, R_c^b row-major")
            nominal = np.asarray(mount_matrix, dtype=np.float64).reshape(3, 3)
        elif mount in MOUNT_PRESETS:
            nominal = MOUNT_PRESETS[mount]
        else:
            choices = ", ".join(MOUNT_CHOICES)
            raise InputError(f"MOUNT '{mount}' is unknown; choose one of {choices}")
        return cls(
            np.asarray(lever_arm, dtype=np.float64), nominal, np.radians(np.asarray(boresight_deg))
        )
