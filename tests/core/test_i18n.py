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
from lidarphoto.core.quality.calibration_html import render_calibration_html
from lidarphoto.core.quality.control_location_html import render_location_html
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


def test_calibration_and_location_reports_in_portuguese(portuguese):
    """calibratecamera's and locatecontrolpoints' pages follow the language (lang attribute,
    headings, the verdict words), and the numbers keep their place in the text."""
    from types import SimpleNamespace as S

    cam = S(name="c", projection="perspective", focal_px=1000.0, pixel_size_mm=0.004,
            principal_point_px=(640.0, 480.0), interior_names=("focal_mm", "k1"),
            interior_params=np.array([4.0, 1e-3]))  # fmt: skip
    result = S(camera=cam, sigmas={"focal_mm": 0.001, "k1": 1e-4}, t_values={"k1": 10.0},
               significant={"k1": True}, parameter_names=["focal_mm", "k1"],
               correlation=np.eye(2), sigma0=1.0, sigma_px=0.2, redundancy=10, rms_px=0.2,
               n_points=20, t_critical=2.0, view_names=["a"], view_points=np.array([20]),
               view_rms_px=np.array([0.2]), eo=np.zeros((1, 6)), warnings=["w"],
               adjustment=S(global_test=S(passed=True)))  # fmt: skip
    page = render_calibration_html(result, {"target": "chessboard"})
    assert '<html lang="pt-BR">' in page
    assert "<h1>Calibração de câmera: c (perspective)</h1>" in page
    for text in ("<h2>Orientação interior</h2>", "<h2>Vistas</h2>", "<h2>Avisos</h2>",
                 "ponto principal (640.00, 480.00) px", "teste global aprovado",
                 "significativo"):  # fmt: skip
        assert text in page, text
    for text in ("Camera calibration", "<h2>Views</h2>", "principal point", "passed"):
        assert text not in page, text
    page = render_location_html([], {"chips": "3"})
    assert '<html lang="pt-BR">' in page
    assert "<h1>Localização de pontos de controle</h1>" in page
    assert "<h2>Galeria de recortes (chips)</h2>" in page
    assert "Control point location" not in page and "Chip gallery" not in page


def test_standard_verdicts_in_portuguese():
    """The standards' fixed texts (titles, check names, status words, notes) are translated
    when shown; the results themselves stay English."""
    rng = np.random.default_rng(5)
    ref = np.column_stack([rng.uniform(0, 900, 12), rng.uniform(0, 900, 12),
                           rng.uniform(0, 9, 12)])  # fmt: skip
    cp = CheckPoints(tuple(f"p{k}" for k in range(12)), ref + rng.normal(0, 0.05, ref.shape),
                     ref, ("a",) * 12, "EPSG:31983", "test")  # fmt: skip
    report = assess_accuracy(cp, AccuracySettings(pec_scale=2000))
    english = render_html(report)
    assert "Check-point count" in english and "<h1>Positional accuracy report</h1>" in english
    i18n.set_language("pt_BR")
    try:
        page = render_html(report)
    finally:
        i18n.set_language("en")
    for text in ("<h1>Relatório de acurácia posicional</h1>",
                 "Padrões de Acurácia Posicional da ASPRS, Edição 2 (2023)",
                 "Número de pontos de verificação", "Acurácia tridimensional",
                 "a Edição 2 não usa mais valores com 95 % de confiança"):  # fmt: skip
        assert text in page, text
    for text in ("Check-point count", "Three-dimensional accuracy", "Positional accuracy"):
        assert text not in page, text
    assert report.settings.title == "Positional accuracy report"
    assert report.standards[0].verdicts[0].name == "Check-point count"


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
