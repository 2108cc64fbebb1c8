"""The algorithms' documentation as local HTML pages, made from the same spec as the QGIS
help and the command line's ``--help``, so that every Help button answers offline.

:func:`help_page` gives one algorithm's page (its description, how to use it, the parameter
table with defaults, units and ranges, the references, how to run it from ``qgis_process``
and the command line); :func:`index_page` the list of all algorithms. :func:`write_help_pages`
writes them into a folder (each file whole or not at all), which the Processing provider
does once per version and language in the user's QGIS profile.
"""

from __future__ import annotations

import html
import os
from collections.abc import Callable, Iterable
from pathlib import Path

from .spec import AlgorithmSpec

#: The stylesheet of every page: readable in a browser and in QGIS's own help viewer.
_STYLE = (
    "body{font-family:sans-serif;max-width:60em;margin:1em auto;padding:0 1em;"
    "line-height:1.4}table{border-collapse:collapse}td,th{border:1px solid #bbb;"
    "padding:.2em .4em;vertical-align:top;text-align:left}th{background:#eee}"
    "code,pre{background:#f4f4f4;padding:.1em .3em}"
)

INDEX_NAME = "index.html"


def page_name(spec: AlgorithmSpec) -> str:
    """The file name of the algorithm's page: ``<algorithm id>.html``."""
    return f"{spec.name}.html"


def _document(title: str, body: str, lang: str) -> str:
    return (
        f'<!DOCTYPE html>\n<html lang="{html.escape(lang.replace("_", "-"))}">\n<head>'
        f'<meta charset="utf-8"><title>{html.escape(title)}</title>'
        f"<style>{_STYLE}</style></head>\n<body>\n{body}\n</body>\n</html>\n"
    )


def help_page(
    spec: AlgorithmSpec,
    help_html: str,
    title: str | None = None,
    tr: Callable[[str], str] | None = None,
    lang: str = "en",
) -> str:
    """The whole HTML page of ``spec``: ``help_html`` is the help body as QGIS shows it
    (:meth:`AlgorithmSpec.help_html`, translated); ``title`` the translated display name;
    ``tr`` translates the page's fixed words."""
    t = tr or (lambda s: s)
    name = html.escape(spec.name)
    heading = html.escape(title or spec.title)
    run = (
        f"<h3>{html.escape(t('Run it'))}</h3><p>{html.escape(t('QGIS: Processing Toolbox'))}"
        f" &rarr; {html.escape(t('LiDAR Photogrammetry'))} &rarr; {heading}</p>"
        f"<pre>qgis_process run lidarphoto:{name} -- ...\nlidarphoto {name} --help</pre>"
    )
    back = f'<p><a href="{INDEX_NAME}">{html.escape(t("All algorithms"))}</a></p>'
    body = f"{back}<h1>{heading}</h1>\n{help_html}\n{run}"
    return _document(f"{title or spec.title} (lidarphoto:{spec.name})", body, lang)


def index_page(
    entries: Iterable[tuple[AlgorithmSpec, str, str]],
    tr: Callable[[str], str] | None = None,
    lang: str = "en",
) -> str:
    """The list of the algorithms, grouped as the toolbox: ``entries`` are (spec, its
    translated display name, its translated group)."""
    t = tr or (lambda s: s)
    groups: dict[str, list[str]] = {}
    for spec, title, group in entries:
        link = f'<li><a href="{page_name(spec)}">{html.escape(title)}</a> ({spec.name})</li>'
        groups.setdefault(group, []).append(link)
    body = "".join(
        f"<h3>{html.escape(group)}</h3><ul>{''.join(items)}</ul>" for group, items in groups.items()
    )
    title = t("LiDAR Photogrammetry Toolkit: algorithms")
    return _document(title, f"<h1>{html.escape(title)}</h1>\n{body}", lang)


def write_help_pages(folder: Path, pages: dict[str, str]) -> None:
    """Write ``pages`` (file name -> HTML) into ``folder``, each through a temporary file
    renamed over the target, so that a reader (or a second QGIS) never sees half a page."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in pages.items():
        target = folder / name
        part = folder / f".{name}.{os.getpid()}.part"
        part.write_text(text, encoding="utf-8")
        os.replace(part, target)
