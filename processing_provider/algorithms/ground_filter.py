"""lidarphoto:groundfilter - ground filter of a LAS/LAZ cloud (SMRF, PMF or cloth simulation);
and one algorithm per method (groundfiltersmrf, groundfilterpmf, groundfiltercsf), whose forms
show that method's fields only, as QGIS's own PDAL algorithms do."""

from __future__ import annotations

from qgis.core import QgsProcessingAlgorithm
from qgis.PyQt.QtCore import QCoreApplication

from ...core.jobs import ground_filter
from ..base import BaseAlgorithm
from ..layer_styles import style_dtm


class GroundFilterAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.ground_filter``: file outputs, the DTM styled when QGIS loads it.

    The toolbox shows the one-method algorithms below; this one (every method's fields, the
    method chosen) stays for models, scripts and ``qgis_process``."""

    JOB = ground_filter
    STYLES = (("OUTPUT_DTM", style_dtm),)

    def flags(self):
        return super().flags() | QgsProcessingAlgorithm.Flag.FlagHideFromToolbox


def _titles() -> dict[str, str]:
    """The one-method algorithms' names (literal, so that ``make i18n`` collects them)."""
    return {
        "smrf": QCoreApplication.translate(
            "GroundFilterMethodAlgorithm", "Ground filter: SMRF (Pingel et al. 2013)"
        ),
        "pmf": QCoreApplication.translate(
            "GroundFilterMethodAlgorithm",
            "Ground filter: progressive morphological (Zhang et al. 2003)",
        ),
        "csf": QCoreApplication.translate(
            "GroundFilterMethodAlgorithm", "Ground filter: cloth simulation (Zhang et al. 2016)"
        ),
    }


class GroundFilterMethodAlgorithm(GroundFilterAlgorithm):
    """``groundfilter`` with METHOD fixed to :attr:`METHOD`: the form holds the common
    fields and that method's only (the other methods' keep their defaults)."""

    METHOD = "smrf"

    def flags(self):
        return BaseAlgorithm.flags(self)

    def name(self) -> str:
        return f"{self.spec.name}{self.METHOD}"

    def displayName(self) -> str:
        return _titles()[self.METHOD]

    def helpUrl(self) -> str:
        from ..help_docs import help_url

        return help_url(self.spec.name)

    def shown(self, name: str) -> bool:
        """Whether parameter ``name`` belongs to the form of this method."""
        if name == "METHOD":
            return False
        return ground_filter.PARAM_METHODS.get(name, "") in ("", self.METHOD)

    def prepare(self, raw: dict, parameters, context, feedback) -> dict:
        return {**raw, "METHOD": self.METHOD}


class GroundFilterSmrfAlgorithm(GroundFilterMethodAlgorithm):
    METHOD = "smrf"


class GroundFilterPmfAlgorithm(GroundFilterMethodAlgorithm):
    METHOD = "pmf"


class GroundFilterCsfAlgorithm(GroundFilterMethodAlgorithm):
    METHOD = "csf"


#: More algorithms of this job (the provider adds them after :class:`GroundFilterAlgorithm`).
EXTRA_ALGORITHMS = (GroundFilterSmrfAlgorithm, GroundFilterPmfAlgorithm, GroundFilterCsfAlgorithm)
