"""The HTML pieces every report shares: escaped text and a table whose first column is the
row's name (class ``t``) and whose rows may carry a CSS class (``pass``, ``fail``...)."""

from __future__ import annotations

import html
from collections.abc import Sequence
from typing import TYPE_CHECKING

from ..i18n import html_lang, render

if TYPE_CHECKING:
    from ..lsq.results import RejectionTest

__all__ = [
    "TR_CONTEXT",
    "escape",
    "failed_checks",
    "html_lang",
    "rejections_explained",
    "report_css",
    "t",
    "table",
]
#: translation context of the reports' texts (``make i18n`` collects the ``t("...")`` calls of
#: every module that defines or imports TR_CONTEXT)
TR_CONTEXT = "Report"


def t(text: object) -> str:
    """``text`` in the language of the reports (:func:`core.i18n.set_language`); a
    :class:`core.i18n.Message` through its translated template and its values."""
    return render(text, TR_CONTEXT)


def report_css(max_width_px: int, rest: str, *, h2_top_px: int = 26, h3: str = "") -> str:
    """The reports' style sheet: page, headings, tables and the pass/fail row colours they
    all share, then ``rest`` (the report's own classes, straight after ``.fail``); ``h3``
    the style of third-level headings where a report has them.

    >>> report_css(1100, ".note{color:#444}").splitlines()[-1]
    '.pass{background:#d8f0d8}.fail{background:#f7d4d4}.note{color:#444}'
    """
    return (
        f"\nbody{{font-family:sans-serif;margin:24px;color:#222;max-width:{max_width_px}px}}\n"
        f"h1{{font-size:22px}}h2{{font-size:18px;border-bottom:1px solid #aaa;"
        f"margin-top:{h2_top_px}px}}\n"
        + (f"{h3}\n" if h3 else "")
        + "table{border-collapse:collapse;margin:8px 0 16px 0;font-size:13px}\n"
        "th,td{border:1px solid #bbb;padding:3px 7px;text-align:right}\n"
        "th{background:#eee}td.t,th.t{text-align:left}\n"
        # printed (the PDF): a heading stays with what follows, a plot or row is not cut
        "h2,h3{page-break-after:avoid}svg,tr{page-break-inside:avoid}\n"
        ".pass{background:#d8f0d8}.fail{background:#f7d4d4}" + rest + "\n"
    )


def escape(text: object) -> str:
    """``text`` as HTML text (quotes escaped too, so it may stand in an attribute).

    >>> escape('a < b & "c"')
    'a &lt; b &amp; &quot;c&quot;'
    """
    return html.escape(str(text), quote=True)


def table(
    header: Sequence[str], rows: Sequence[Sequence[str]], css: Sequence[str] | None = ()
) -> str:
    """A ``<table>`` of already formatted (escaped) cells; ``css[k]`` is row k's class.

    >>> table(["id", "dX"], [["p1", "0.10"]], ["fail"]).split("<tbody>")[1]
    '<tr class="fail"><td class="t">p1</td><td>0.10</td></tr></tbody></table>'
    """
    css = css or ()
    head = "".join(
        f'<th class="t">{h}</th>' if i == 0 else f"<th>{h}</th>" for i, h in enumerate(header)
    )
    body = []
    for k, row in enumerate(rows):
        cls = f' class="{css[k]}"' if k < len(css) and css[k] else ""
        cells = "".join(
            f'<td class="t">{c}</td>' if i == 0 else f"<td>{c}</td>" for i, c in enumerate(row)
        )
        body.append(f"<tr{cls}>{cells}</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def failed_checks(problems: Sequence[object], accepted: bool, refused: str) -> list[str]:
    """The alarm at the top of a report whose results failed their checks (``problems``:
    why; nothing when there are none): written anyway because the user asked (``accepted``),
    or not written (``refused``: the translated sentence saying what was not)."""
    if not problems:
        return []
    verdict = refused
    if accepted:
        verdict = t(
            "These results FAILED their checks and were written only because the user asked "
            "for them (ACCEPT_DOUBTFUL): do not use them without review."
        )
    items = "".join(f"<li>{escape(t(p))}</li>" for p in problems)
    return [f'<div class="alarm"><p><b>{escape(verdict)}</b></p><ul>{items}</ul></div>']


def rejections_explained(test: RejectionTest) -> str:
    """The count test of data snooping's rejections in one translated line: the most that its
    false alarms explain, how many they are expected to be, how many were rejected and the
    probability of that many."""
    return t("at most {bound} ({expected} expected); {k} rejected: P = {p}").format(
        bound=test.bound,
        expected=f"{test.expected:.2g}",
        k=test.rejected,
        p=f"{test.p_value:.2g}",
    )
