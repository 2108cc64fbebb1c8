"""The Help button of every algorithm: a local HTML page made from the algorithm's spec
(``core/jobs/help_pages.py``) in QGIS's language, written once per plugin version and
language into the user's QGIS profile, so that the documentation is there offline."""

from __future__ import annotations

from pathlib import Path

from qgis.core import QgsApplication
from qgis.PyQt.QtCore import QCoreApplication, QUrl

from ..core import __version__
from ..core import i18n as core_i18n
from ..core.jobs import algorithms
from ..core.jobs.help_pages import INDEX_NAME, help_page, index_page, page_name, write_help_pages
from ..core.jobs.translate import translate_spec
from .i18n import help_tr, spec_translator

#: Folders written by this process (a page is made once per process, version and language).
_written: dict[str, Path] = {}


def help_folder(lang: str) -> Path:
    """``<QGIS profile>/lidarphoto/help/<version>/<language>``."""
    root = Path(QgsApplication.qgisSettingsDirPath())
    return root / "lidarphoto" / "help" / __version__ / lang


def pages(lang: str) -> dict[str, str]:
    """Every algorithm's page and the index, in the installed language."""
    out: dict[str, str] = {}
    entries = []
    for job in algorithms():
        spec = job.SPEC
        tr = spec_translator(spec)
        title, group = tr(spec.title), tr(spec.group)
        body = translate_spec(spec, QCoreApplication.translate).help_html(help_tr)
        out[page_name(spec)] = help_page(spec, body, title, help_tr, lang)
        entries.append((spec, title, group))
    out[INDEX_NAME] = index_page(entries, help_tr, lang)
    return out


def ensure_help_pages() -> Path:
    """The folder of the help pages in the current language, written on first use in this
    process (so a page always matches the specs of the plugin that runs)."""
    lang = core_i18n.current_language()
    folder = _written.get(lang)
    if folder is None:
        folder = help_folder(lang)
        write_help_pages(folder, pages(lang))
        _written[lang] = folder
    return folder


def help_url(name: str) -> str:
    """The file URL of algorithm ``name``'s page ("" when the pages cannot be written: QGIS
    then greys the Help button out instead of opening a dead link)."""
    try:
        folder = ensure_help_pages()
    except OSError:
        return ""
    page = folder / f"{name}.html"
    return QUrl.fromLocalFile(str(page)).toString() if page.is_file() else ""
