"""Translating a job's spec: the texts a user reads (title, group, summary, description,
labels, help, option labels, result labels), one message each, in the context
``lidarphoto:<algorithm>``.

The description is translated paragraph by paragraph (blocks separated by a blank line), so
that changing one paragraph asks for one new translation. Names, ids, option names, units
and defaults are API and stay as they are.

:func:`spec_messages` lists the messages (``make i18n`` writes them into the .ts file, since
Qt's lupdate cannot see text that is not in a ``tr()`` call); :func:`translate_spec` returns a
copy of a spec with every message passed through ``translate(context, text)``: the
Processing provider gives ``QCoreApplication.translate``, the command line the core's
catalogue (:mod:`core.i18n`).
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable, Iterator

from .spec import TR_CONTEXT, AlgorithmSpec

__all__ = ["HELP_CONTEXT", "context_of", "spec_messages", "translate_spec"]

#: Context of the fixed words of the generated help (see ``AlgorithmSpec.help_html``).
HELP_CONTEXT = TR_CONTEXT
_BLOCKS = re.compile(r"\n\s*\n")


def context_of(spec: AlgorithmSpec) -> str:
    """The translation context of an algorithm: its QGIS id (``lidarphoto:groundfilter``)."""
    return f"lidarphoto:{spec.name}"


def _blocks(text: str) -> list[str]:
    return [b for b in _BLOCKS.split(text.strip()) if b.strip()]


def spec_messages(spec: AlgorithmSpec) -> Iterator[str]:
    """Every translatable text of ``spec`` in order (repeats removed)."""
    seen: set[str] = set()
    items = [spec.title, spec.group, spec.summary, *_blocks(spec.description)]
    for p in spec.params:
        items += [p.label, p.help, *p.labels, p.file_filter]
    items += [r.label for r in spec.results]
    for text in items:
        if text and text not in seen:
            seen.add(text)
            yield text


def translate_spec(spec: AlgorithmSpec, translate: Callable[[str, str], str]) -> AlgorithmSpec:
    """A copy of ``spec`` with its texts translated by ``translate(context, text)``.

    >>> from lidarphoto.core.jobs import ALGORITHMS
    >>> spec = ALGORITHMS[0].SPEC
    >>> upper = translate_spec(spec, lambda ctx, text: text.upper())
    >>> upper.title == spec.title.upper(), upper.name == spec.name
    (True, True)
    """
    ctx = context_of(spec)

    def tr(text: str) -> str:
        return translate(ctx, text) if text else text

    params = tuple(
        dataclasses.replace(
            p,
            label=tr(p.label),
            help=tr(p.help),
            labels=tuple(tr(t) for t in p.labels),
            file_filter=tr(p.file_filter),
        )
        for p in spec.params
    )
    results = tuple(dataclasses.replace(r, label=tr(r.label)) for r in spec.results)
    description = "\n\n".join(tr(b) for b in _blocks(spec.description))
    return dataclasses.replace(
        spec,
        title=tr(spec.title),
        group=tr(spec.group),
        summary=tr(spec.summary),
        description=description,
        params=params,
        results=results,
    )
