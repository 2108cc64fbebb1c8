"""Qt's translation of the toolkit: the translator of QGIS's language and the algorithms'
spec texts through ``QCoreApplication.translate``.

The compiled catalogue ``i18n/lidarphoto_<lang>.qm`` (built from the .ts by ``make package``,
``make i18n`` and the test set-up; see README, Developers) is installed once per process,
by the Processing provider (so qgis_process, which loads no GUI, speaks the language too) or
by the plugin's initGui, whichever comes first. The same language is given to the core
(:func:`core.i18n.set_language`) for the HTML reports.
"""

from __future__ import annotations

from collections.abc import Callable

from qgis.core import QgsApplication, QgsSettings
from qgis.PyQt.QtCore import QCoreApplication, QTranslator

from ..core import i18n as core_i18n
from ..core.jobs.spec import TR_CONTEXT as HELP_CONTEXT
from ..core.jobs.spec import AlgorithmSpec
from ..core.jobs.translate import context_of, translate_spec

__all__ = [
    "help_tr",
    "install_translator",
    "qgis_language",
    "spec_help_html",
    "spec_translator",
]

_installed: dict[str, QTranslator] = {}


def qgis_language() -> str:
    """QGIS's user-interface language (``pt_BR``, ``en``...): the ``locale/userLocale``
    setting when the user overrides the system locale, else the system's language."""
    settings = QgsSettings()
    if settings.value("locale/overrideFlag", False, type=bool):
        user = settings.value("locale/userLocale", "", type=str)
        if user:
            return user
    return QgsApplication.locale() or "en"


def install_translator(lang: str | None = None) -> str:
    """Install the toolkit's Qt translator for ``lang`` (default: QGIS's language) once.

    Returns the language used (``en`` when there is no catalogue or no compiled .qm).
    """
    name = core_i18n.normalise_language(lang or qgis_language())
    core_i18n.set_language(name)
    if name == "en" or name in _installed:
        return name
    qm = core_i18n.I18N_DIR / f"{core_i18n.PREFIX}{name}.qm"
    translator = QTranslator()
    if not qm.is_file() or not translator.load(str(qm)):
        # a checkout linked into QGIS has no .qm (built by `make package`): read the .ts
        translator = CatalogueTranslator(name)
        if not core_i18n.catalogue(name):
            return "en"
    for other in list(_installed):  # one language at a time
        QCoreApplication.removeTranslator(_installed.pop(other))
    QCoreApplication.installTranslator(translator)
    _installed[name] = translator  # the translator must outlive this call
    return name


class CatalogueTranslator(QTranslator):
    """The translations of ``i18n/lidarphoto_<lang>.ts`` read directly (the core's parser of
    the catalogue), for a plugin folder whose .qm has not been compiled."""

    def __init__(self, lang: str) -> None:
        super().__init__()
        self.table = core_i18n.catalogue(lang)

    def translate(self, context, source, disambiguation=None, n=-1):
        return self.table.get((context, source), "")  # "" : Qt keeps the source text

    def isEmpty(self) -> bool:
        return not self.table


def remove_translator() -> None:
    """Remove the installed translator (tests; the plugin keeps it until QGIS exits)."""
    for name in list(_installed):
        QCoreApplication.removeTranslator(_installed.pop(name))
    core_i18n.set_language("en")


def spec_translator(spec: AlgorithmSpec) -> Callable[[str], str]:
    """``tr(text)`` for the texts of ``spec`` (context ``lidarphoto:<algorithm>``)."""
    ctx = context_of(spec)

    def tr(text: str) -> str:
        return QCoreApplication.translate(ctx, text) if text else text

    return tr


def help_tr(text: str) -> str:
    """Translate a fixed word of the generated help (context ``AlgorithmHelp``)."""
    return QCoreApplication.translate(HELP_CONTEXT, text)


def spec_help_html(spec: AlgorithmSpec) -> str:
    """The algorithm's help (HTML) in QGIS's language."""
    return translate_spec(spec, QCoreApplication.translate).help_html(help_tr)
