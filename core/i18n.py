"""Translations of the core's user-facing text (algorithm help, HTML reports), without Qt.

The plugin's one catalogue per language is the Qt Linguist file
``i18n/lidarphoto_<lang>.ts`` (XML, in the repository; ``make i18n`` updates it from the
code). QGIS loads the compiled ``.qm`` through a ``QTranslator``; the core reads the same
``.ts`` with ElementTree, so the command line and the HTML reports speak the language QGIS
shows without importing Qt. A message is found by (context, source text); unfinished or
empty translations are ignored (the English text is shown).

Contexts used by the core: ``lidarphoto:<algorithm>`` (the strings of a job's spec,
:mod:`core.jobs.translate`), ``AlgorithmHelp`` (the fixed words of the generated help) and
``Report`` (the HTML reports).

The language of the reports is process-wide (:func:`set_language`): the Processing provider
sets it from QGIS's locale, the command line from ``--lang`` or ``LANG``.
"""

from __future__ import annotations

import functools
import os
import xml.etree.ElementTree as ET
from collections.abc import Callable
from pathlib import Path

__all__ = [
    "I18N_DIR",
    "available_languages",
    "catalogue",
    "current_language",
    "html_lang",
    "language_from_env",
    "normalise_language",
    "set_language",
    "translator",
]

#: Folder of the .ts (and, once built, .qm) files: ``<plugin>/i18n``.
I18N_DIR = Path(__file__).resolve().parents[1] / "i18n"
PREFIX = "lidarphoto_"
_language = "en"


def available_languages() -> tuple[str, ...]:
    """Languages that have a catalogue, e.g. ``("pt_BR",)`` (English is the source)."""
    return tuple(sorted(p.stem[len(PREFIX) :] for p in I18N_DIR.glob(PREFIX + "*.ts")))


def normalise_language(lang: str | None) -> str:
    """A locale name (``pt_BR.UTF-8``, ``pt-br``, ``pt``, ``C``) -> the catalogue to use.

    A bare language picks its one country variant (``pt`` -> ``pt_BR``); anything without
    a catalogue is English (``en``).

    >>> normalise_language("pt_BR.UTF-8"), normalise_language("C"), normalise_language(None)
    ('pt_BR', 'en', 'en')
    """
    if not lang:
        return "en"
    name = lang.split(".")[0].split("@")[0].replace("-", "_")
    if "_" in name:
        code, country = name.split("_", 1)
        name = f"{code.lower()}_{country.upper()}"
    else:
        name = name.lower()
    known = available_languages()
    if name in known:
        return name
    base = name.split("_")[0]
    matches = [k for k in known if k.split("_")[0] == base]
    return matches[0] if matches else "en"


def language_from_env(environ: os._Environ | dict | None = None) -> str:
    """The language of the environment (``LC_ALL``, ``LC_MESSAGES``, ``LANG``), normalised."""
    env = os.environ if environ is None else environ
    for key in ("LC_ALL", "LC_MESSAGES", "LANG"):
        if env.get(key):
            return normalise_language(env[key])
    return "en"


def set_language(lang: str | None) -> str:
    """Set the language of the core's text for this process; returns the normalised name."""
    global _language
    _language = normalise_language(lang)
    return _language


def current_language() -> str:
    """The language set by :func:`set_language` (``en`` by default)."""
    return _language


def html_lang(lang: str | None = None) -> str:
    """The ``lang`` attribute of an HTML page in ``lang`` (default: the current language).

    >>> html_lang("en")
    'en'
    """
    return normalise_language(lang or _language).replace("_", "-")


@functools.lru_cache(maxsize=8)
def catalogue(lang: str) -> dict[tuple[str, str], str]:
    """{(context, source): translation} of the finished translations of ``lang``.

    Empty for English or a language without a catalogue.
    """
    lang = normalise_language(lang)
    path = I18N_DIR / f"{PREFIX}{lang}.ts"
    if lang == "en" or not path.is_file():
        return {}
    out: dict[tuple[str, str], str] = {}
    for ctx in ET.parse(path).getroot().iter("context"):
        name = ctx.findtext("name", "")
        for msg in ctx.iter("message"):
            tr = msg.find("translation")
            if tr is None or tr.get("type") in ("unfinished", "vanished", "obsolete"):
                continue
            text = tr.text or ""
            if text:
                out[(name, msg.findtext("source", ""))] = text
    return out


def translator(context: str, lang: str | None = None) -> Callable[[str], str]:
    """``tr(text)`` translating into ``lang`` (default: :func:`current_language`) in
    ``context``; the text itself when there is no translation.

    >>> translator("Report", "en")("Settings")
    'Settings'
    """
    table = catalogue(normalise_language(lang or _language))

    def tr(text: str) -> str:
        return table.get((context, text), text)

    return tr
