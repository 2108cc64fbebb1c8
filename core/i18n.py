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
    "Message",
    "available_languages",
    "catalogue",
    "current_language",
    "html_lang",
    "joined",
    "language_from_env",
    "log_text",
    "mark",
    "normalise_language",
    "render",
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


def _message(template: str, values: dict) -> Message:
    return Message(template, **values)


class Message(str):
    """An English sentence made from a template marked for translation and its values.

    It *is* the English text (a ``str``: JSON, CSV and logs see plain English), and it keeps
    ``template`` and ``values`` so that a report shows it in the user's language with
    :func:`render`: the template is translated, then formatted with the values (a value that
    is itself a :class:`Message` is rendered too). Modules that build such sentences mark
    them ``_t("RMSE {value:.3f} m", value=x)`` so that ``make i18n`` collects the template.

    >>> m = Message("{n} points beyond {limit:.2f} m", n=3, limit=0.4)
    >>> m, m.template, m.values["n"]
    ('3 points beyond 0.40 m', '{n} points beyond {limit:.2f} m', 3)
    """

    template: str
    values: dict

    def __new__(cls, template: str, /, **values: object) -> Message:
        self = super().__new__(cls, template.format(**values) if values else template)
        self.template = template
        self.values = values
        return self

    def __reduce__(self):  # pickling (worker processes) and deepcopy keep the template
        return (_message, (self.template, dict(self.values)))


def mark(template: str, /, **values: object) -> Message:
    """A sentence marked for translation: modules import it as ``_t`` (``make i18n`` collects
    ``_t("...")`` in modules that set ``TR_CONTEXT``) and build ``_t("{n} points", n=3)``."""
    return Message(template, **values)


def joined(items, sep: str = ", ") -> Message:
    """Sentences joined by ``sep``, each rendered in the report's language (a list of
    :class:`Message` inside another one's value).

    >>> joined([Message("{a} of group {g}", a="d_phi", g="1"), "x"])
    'd_phi of group 1, x'
    """
    items = list(items)
    template = sep.join("{" + f"v{k}" + "}" for k in range(len(items)))
    return Message(template, **{f"v{k}": item for k, item in enumerate(items)})


def render(text: object, context: str, lang: str | None = None) -> str:
    """``text`` in ``lang`` (default: :func:`current_language`): a :class:`Message` through its
    translated template and its (rendered) values, any other text looked up as it is.

    A translation whose placeholders do not fit the values falls back to the English text.

    >>> render(Message("{n} of {total} points", n=2, total=5), "Report", "en")
    '2 of 5 points'
    """
    tr = translator(context, lang)
    if not isinstance(text, Message):
        return tr(str(text))
    if not text.values:
        return tr(text.template)
    values = {
        k: render(v, context, lang) if isinstance(v, Message) else v for k, v in text.values.items()
    }
    try:
        return tr(text.template).format(**values)
    except (KeyError, IndexError, ValueError):
        return text.template.format(**values)


def log_text(record, context: str = "Report", lang: str | None = None) -> str:
    """The text of a ``logging.LogRecord`` in ``lang`` (default: the current language): its
    message and arguments that are :class:`Message` are rendered; the rest is formatted as
    ``logging`` does. The Processing provider's log bridge shows core logs through it.

    >>> import logging
    >>> args = ("P1", Message("n = {n}", n=2))
    >>> rec = logging.LogRecord("x", 20, "", 0, "point %s: %s", args, None)
    >>> log_text(rec, lang="en")
    'point P1: n = 2'
    """
    msg = record.msg
    args = record.args
    if isinstance(msg, Message):
        msg = render(msg, context, lang)
    if isinstance(args, tuple):
        args = tuple(render(a, context, lang) if isinstance(a, Message) else a for a in args)
    if not args:
        return str(msg)
    try:
        return str(msg) % args
    except (TypeError, ValueError):  # a translation that broke the %-format: the English
        return record.getMessage()
