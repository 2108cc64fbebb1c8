"""The core's translations (no Qt): the catalogue read from i18n/*.ts, the reports and the
command line in Brazilian Portuguese, English by default."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core import i18n
from lidarphoto.core.cli import build_parser
from lidarphoto.core.jobs import ALGORITHMS
from lidarphoto.core.jobs.translate import context_of, spec_messages, translate_spec
from lidarphoto.core.quality.accuracy import AccuracySettings, CheckPoints, assess_accuracy
from lidarphoto.core.quality.accuracy_html import render_html
from lidarphoto.core.quality.resection_html import render_resection_html


@pytest.fixture()
def portuguese():
    assert i18n.set_language("pt_BR") == "pt_BR"
    yield
    i18n.set_language("en")


def test_language_names():
    assert i18n.available_languages() == ("pt_BR",)
    assert i18n.normalise_language("pt") == "pt_BR"
    assert i18n.normalise_language("pt-br") == "pt_BR"
    assert i18n.normalise_language("de_DE.UTF-8") == "en"
    assert i18n.language_from_env({"LANG": "pt_BR.UTF-8"}) == "pt_BR"
    assert i18n.language_from_env({"LC_ALL": "C", "LANG": "pt_BR.UTF-8"}) == "en"
    assert i18n.language_from_env({}) == "en"


def test_catalogue_translates_every_spec_text():
    """Every text of every algorithm's spec has a Portuguese translation in its context, and
    translate_spec uses it: nothing of the spec stays English in pt_BR (names stay)."""
    table = i18n.catalogue("pt_BR")
    for job in ALGORITHMS:
        spec = job.SPEC
        for text in spec_messages(spec):
            assert (context_of(spec), text) in table, (spec.name, text[:60])
        pt = translate_spec(spec, lambda c, s: table.get((c, s), s))
        assert pt.name == spec.name and [p.name for p in pt.params] == [
            p.name for p in spec.params
        ]
        assert pt.title != spec.title
        changed = sum(a.label != b.label for a, b in zip(pt.params, spec.params))
        assert changed >= len(spec.params) // 2, spec.name  # units-only labels may stay


def test_resection_report_in_portuguese(portuguese):
    page = render_resection_html([], [], {"camera": "c"})
    assert '<html lang="pt-BR">' in page
    assert "<h1>Resseção espacial</h1>" in page and "<h2>Configurações</h2>" in page
    assert "Space resection" not in page and "Settings" not in page


def test_accuracy_report_in_portuguese_and_english():
    rng = np.random.default_rng(3)
    ref = np.column_stack([500000 + rng.uniform(0, 900, 12), 7450000 + rng.uniform(0, 900, 12),
                           rng.uniform(0, 9, 12)])  # fmt: skip
    meas = ref + rng.normal(0, 0.05, ref.shape)
    ids = tuple(f"p{k}" for k in range(12))
    cp = CheckPoints(ids, meas, ref, ("a",) * 12, "EPSG:31983", "test")
    report = assess_accuracy(cp, AccuracySettings(pec_scale=2000))
    english = render_html(report)
    assert '<html lang="en">' in english and "<h2>Summary</h2>" in english
    i18n.set_language("pt_BR")
    try:
        page = render_html(report)
    finally:
        i18n.set_language("en")
    assert '<html lang="pt-BR">' in page
    for text in ("<h2>Resumo</h2>", "<h2>Estatísticas</h2>", "Pontos de verificação", "Notas"):
        assert text in page, text
    for text in ("<h2>Summary</h2>", "<h2>Statistics</h2>", "<h2>Notes</h2>"):
        assert text not in page, text
    # the numbers are the same in both languages
    assert english.count("<td>") == page.count("<td>")


def test_command_line_help_in_portuguese(capsys):
    parser = build_parser("pt_BR")
    with pytest.raises(SystemExit):
        parser.parse_args(["createlcps", "--help"])
    out = capsys.readouterr().out
    assert "Intersecta os planos de telhado" in out
    assert "Fronteira comum mínima" in out
    assert "--min-boundary" in out  # options stay as they are
    parser = build_parser("en")
    with pytest.raises(SystemExit):
        parser.parse_args(["createlcps", "--help"])
    assert "Intersects roof planes" in capsys.readouterr().out
