"""The choices and defaults of monoplotting (:mod:`.monoplot`), kept apart from its ray
casting (pyproj, the DSM) so that the algorithm's spec reads them without importing it
(core/jobs/monoplot.py)."""

from __future__ import annotations

#: How a ray meets the surface: Dal Poz's direct DDA traversal or Makarovic's iteration.
METHODS = ("dal_poz", "makarovic")
#: Exterior-orientation sigmas (X, Y, Z m; omega, phi, kappa degrees) of a survey-grade
#: GNSS/INS after post-processing (POS AV 510 class), used when none is given.
DEFAULT_EO_SIGMAS = (0.05, 0.05, 0.08, 0.005, 0.005, 0.008)
