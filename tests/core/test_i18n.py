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


def _in_portuguese(render, *args, **kw):
    """``render(*args, **kw)`` with the reports' language set to pt_BR (English again after)."""
    i18n.set_language("pt_BR")
    try:
        return render(*args, **kw)
    finally:
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
        assert pt.name == spec.name and [p.name for p in pt.params] == [p.name for p in spec.params]
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
    report, english, page = _accuracy_pages(12, 0.05, 5, pec_scale=2000)
    assert "Check-point count" in english and "<h1>Positional accuracy report</h1>" in english
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
    _, english, page = _accuracy_pages(12, 0.05, 3, pec_scale=2000)
    assert '<html lang="en">' in english and "<h2>Summary</h2>" in english
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


# ----------------------------------------------------------------------------- sentences
def _fields(text: str) -> list[tuple[str, str, str]]:
    """The placeholders of a format template: (name, conversion, format spec), sorted."""
    import string

    return sorted(
        (name, conv or "", spec or "")
        for _, name, spec, conv in string.Formatter().parse(text)
        if name is not None
    )


def test_every_translation_keeps_the_placeholders_of_its_source():
    """A translated template has exactly its source's placeholders (names, conversions and
    format specs): otherwise ``t(template).format(**values)`` fails or shows another number.
    Parsed from the .ts by core/i18n.py; every finished message of every context."""
    table = i18n.catalogue("pt_BR")
    assert len(table) > 1300
    bad, templates = [], 0
    for (ctx, source), text in table.items():
        try:
            want = _fields(source)
        except ValueError:  # not a template (an unbalanced brace in prose): braces kept
            if source.count("{") != text.count("{") or source.count("}") != text.count("}"):
                bad.append((ctx, source[:60], "braces"))
            continue
        templates += bool(want)
        try:
            got = _fields(text)
        except ValueError as exc:
            bad.append((ctx, source[:60], str(exc)))
            continue
        if got != want:
            bad.append((ctx, source[:60], got, want))
    assert templates > 100  # the check has something to check
    assert not bad, bad


def test_placeholder_check_catches_a_changed_spec():
    assert _fields("RMSE {rmse:.3f} m {relation} {limit:.3f} m") != _fields(
        "RMSE {rmse:.2f} m {relation} {limit:.3f} m"
    )
    assert _fields("{n} de {total}") != _fields("{n} of {count}")


def test_message_is_english_and_renders_translated():
    m = i18n.Message("{n} check points; NSSDA requires at least {minimum}", n=12, minimum=20)
    assert m == "12 check points; NSSDA requires at least 20"
    import json
    import pickle

    assert json.dumps({"r": m}) == '{"r": "12 check points; NSSDA requires at least 20"}'
    back = pickle.loads(pickle.dumps(m))
    assert back == m and back.template == m.template and back.values == m.values
    assert (
        i18n.render(m, "Report", "pt_BR") == "12 pontos de verificação; o NSSDA exige pelo menos 20"
    )
    assert i18n.render(m, "Report", "en") == m
    # a nested sentence is translated too; an unknown template stays English
    nested = i18n.Message("{axis} class", axis=i18n.Message("Horizontal"))
    assert i18n.render(nested, "Report", "pt_BR") == "Classe horizontal"
    assert i18n.render(i18n.Message("no such {x}", x=1), "Report", "pt_BR") == "no such 1"


def _accuracy_pages(n: int, sigma: float, seed: int, **settings):
    rng = np.random.default_rng(seed)
    ref = np.column_stack([500000 + rng.uniform(0, 900, n), 7450000 + rng.uniform(0, 900, n),
                           rng.uniform(0, 9, n)])  # fmt: skip
    meas = ref + rng.normal(0, sigma, ref.shape)
    cp = CheckPoints(tuple(f"p{k}" for k in range(n)), meas, ref, ("a",) * n, "EPSG:31983",
                     "test")  # fmt: skip
    report = assess_accuracy(cp, AccuracySettings(**settings))
    english = render_html(report)
    page = _in_portuguese(render_html, report)
    return report, english, page


def test_accuracy_verdicts_with_numbers_in_portuguese():
    """ASPRS, NSSDA, PEC-PCD and the project threshold: the class names and the reasons,
    with their numbers, in Portuguese; the English page and the results unchanged."""
    report, english, page = _accuracy_pages(
        12, 0.05, 3, standards=("asprs", "nssda", "pec", "project"), pec_scale=2000,
        asprs_h_class_cm=5.0, asprs_v_class_cm=5.0, pec_class="B",
    )  # fmt: skip
    by = {r.key: r for r in report.standards}
    asprs, nssda, pec, project = by["asprs"], by["nssda"], by["pec"], by["project"]
    f = asprs.figures
    h_cm, v_cm = 100 * f["RMSE_HORIZONTAL_TOTAL"], 100 * f["RMSE_U_TOTAL"]
    share = 100 * pec.figures["planimetric_A_share_within_pec"]
    acc_r = nssda.figures["ACCURACY_HORIZONTAL_95"]
    # the results stay English (JSON, CSV)
    assert asprs.verdicts[0].reason == (
        "12 check points; Edition 2 requires at least 30 (and up to 120 for large projects)"
    )
    assert asprs.verdicts[1].name == "Horizontal class 5-cm"
    expected = [
        "12 pontos de verificação; a Edição 2 exige pelo menos 30 (e até 120 para projetos "
        "grandes)",
        "Classe horizontal de 5 cm",
        "Classe vertical (NVA) de 5 cm",
        f"RMSE_HORIZONTAL_TOTAL (ASPRS RMSE_H) = {h_cm:.2f} cm",
        "; apenas 12 de 30 pontos de verificação",
        f"RMSE_U_TOTAL (ASPRS RMSE_V) = {v_cm:.2f} cm",
        "12 pontos de verificação; o NSSDA exige pelo menos 20",
        "Hipótese: distribuição normal (Shapiro-Wilk)",
        f"Acurácia horizontal testada de {acc_r:.3f} m ao nível de confiança de 95 % (apenas "
        "12 de 20 pontos de verificação)",
        "Classe A planimétrica", "Classe D altimétrica",
        "Classe declarada B (planimétrica)", "Classe declarada B (altimétrica)",
        f"{share:.1f} % de 12 pontos dentro do PEC de 0.560 m",
        "Escala 1:2,000; equidistância 1 m. Melhor classe atendida: planimétrica A",
        f"RMSE {project.figures['RMSE_HORIZONTAL']:.3f} m &lt;= 0.400 m; 0 de 12 pontos além "
        "do limiar",
        "Eq. 18 com H 1600 m, B 452 m, f 100.4 mm, sigma_pix 6 µm",
        "Erro do levantamento dos pontos de verificação incluído",
    ]  # fmt: skip
    for text in expected:
        assert text in page, text
    for text in ("check points; Edition 2", "Horizontal class", "Vertical (NVA) class",
                 "NSSDA requires", "Assumption:", "horizontal accuracy at 95", "Class A",
                 "Declared class", "points within PEC", "Best class met", "points beyond it",
                 "Eq. 18 with", "Check-point survey error", "only 12 of"):  # fmt: skip
        assert text not in page, text
        assert text in english, text


def test_asprs_without_target_class_and_nssda_ratio_in_portuguese():
    report, english, page = _accuracy_pages(35, 0.03, 8, standards=("asprs", "nssda"))
    asprs = report.standards[0]
    h_cm = 100 * asprs.figures["RMSE_HORIZONTAL_TOTAL"]
    ratio = report.standards[1].figures["ratio_min_max"]
    assert (f"RMSE_HORIZONTAL_TOTAL (ASPRS RMSE_H) = {h_cm:.2f} cm: atende a qualquer classe de "
            f"pelo menos {h_cm:.2f} cm") in page  # fmt: skip
    assert "Classe horizontal<" in page and "Classe vertical (NVA)<" in page
    assert f"RMSE_min/RMSE_max = {ratio:.3f} " in page
    assert "meets any class" not in page and "meets any class" in english


def test_calibration_warnings_in_portuguese():
    """calibrate_camera's warnings (a view left out, a coefficient not significant) are
    English in the result and Portuguese in the pt_BR report, numbers in place."""
    pytest.importorskip("cv2")
    from lidarphoto.core.geometry.camera import Camera
    from lidarphoto.core.geometry.distortion import BrownConrady
    from lidarphoto.core.photo.calibration_targets import Detection, TargetSpec, target_field
    from lidarphoto.core.photo.camera_calibration import (
        MIN_POINTS_PER_VIEW,
        CalibrationOptions,
        calibrate_camera,
        look_at_eo,
        simulate_views,
    )

    ps = 0.004
    cam = Camera("t", 1000 * ps, ps, 1280, 960, 0.02, -0.015, BrownConrady(k1=-2e-3))
    fld = target_field(TargetSpec("chessboard", 9, 6, 0.05))
    ctr = fld.xyz.mean(0)
    rng = np.random.default_rng(2)
    eos = []
    for i in range(8):
        az, tilt = 2 * np.pi * i / 8, np.radians(rng.uniform(15, 40))
        c = ctr + 0.6 * np.array([np.sin(tilt) * np.cos(az), np.sin(tilt) * np.sin(az),
                                  np.cos(tilt)])  # fmt: skip
        eos.append(look_at_eo(c, ctr, rng.uniform(-0.5, 0.5)))
    det = simulate_views(cam, fld, np.array(eos), noise_px=0.2, seed=4)
    few = Detection("few", det[0].ids[:3].copy(), det[0].pixels[:3].copy())
    res = calibrate_camera(fld, [*det, few], 1280, 960, ps, CalibrationOptions(sigma_px=0.2))
    left = f"view 'few' left out: fewer than {MIN_POINTS_PER_VIEW} target points"
    assert left in res.warnings
    weak = [w for w in res.warnings if "is not significant" in w]
    assert weak, res.warnings  # p1, p2 (zero in the camera) are not significant
    page = _in_portuguese(render_calibration_html, res, {"target": "chessboard"})
    assert (
        f"vista &#x27;few&#x27; descartada: menos de {MIN_POINTS_PER_VIEW} pontos do alvo" in page
    )
    name = weak[0].values["parameter"]
    t_value, crit = weak[0].values["t"], weak[0].values["critical"]
    assert (f"{name} não é significativo (t = {t_value:.2f} &lt; {crit:.2f}): considere "
            "fixá-lo em zero") in page  # fmt: skip
    assert "left out" not in page and "is not significant" not in page
    english = render_calibration_html(res, {"target": "chessboard"})
    assert "view &#x27;few&#x27; left out" in english


def test_control_location_reasons_in_portuguese():
    """locate_control_points' reasons (a chip without texture, a point outside every image)
    and status words in the pt_BR report; English in the results."""
    from lidarphoto.core.geometry.camera import Camera
    from lidarphoto.core.photo.control_location import ControlChip, locate_control_points
    from lidarphoto.core.photo.orientation import ExteriorOrientationTable

    wkt = "EPSG:31983"
    cam = Camera("c", 0.1, 0.01, 1000, 800)
    eo = ExteriorOrientationTable(("img1",), np.zeros(1), ("",), np.array([[500000.0,
                                  7450000.0, 1000.0]]), np.zeros((1, 3)), wkt)  # fmt: skip
    gt_flat = (499990.0, 0.1, 0.0, 7450010.0, 0.0, -0.1)
    flat = ControlChip("flat", np.full((201, 201), 100.0), gt_flat, [500000.0, 7450000.0, 0.0])
    rr, cc = np.mgrid[0:201, 0:201]
    texture = 120 + 60 * np.sin(cc / 4.0) * np.cos(rr / 5.0) + 30 * np.sin((cc + rr) / 7.0)
    gt_far = (599990.0, 0.1, 0.0, 7450010.0, 0.0, -0.1)
    far = ControlChip("far", texture, gt_far, [600000.0, 7450000.0, 0.0])
    res = locate_control_points([flat, far], eo, cam, lambda *a: np.full((a[4], a[3]), np.nan))
    reasons = {p.point_id: p.reason for p in res.pairs}
    assert reasons == {"flat": "chip refused: no texture", "far": "outside every image"}
    page = _in_portuguese(render_location_html, res.pairs, {"chips": "2"})
    for text in ("recorte (chip) recusado: sem textura", "fora de todas as imagens",
                 "<td>rejeitado</td>", "<td>fora</td>"):  # fmt: skip
        assert text in page, text
    for text in ("chip refused", "no texture", "outside every image", ">rejected<"):
        assert text not in page, text


def test_boresight_doubts_in_portuguese():
    """Why a boresight calibration is refused (global test, an implausible angle), English in
    the error and Portuguese in the pt_BR report, numbers in place."""
    from types import SimpleNamespace as S

    from lidarphoto.core.jobs.boresight_calibration import doubts_about
    from lidarphoto.core.quality.boresight_html import render_boresight_html

    result = S(adjustment=S(converged=True, iterations=4, warnings=[], residuals={}),
               chi2_passed=False,
               sigma0=3.5, groups=("g1",), boresight_deg=np.array([[0.01, 2.5, 0.0]]),
               std=np.full((1, 3), 1e-3))  # fmt: skip
    doubts = doubts_about(result, 1.0, 2.0)
    assert doubts[0].startswith("the global test failed with sigma0 = 3.5 > MAX_SIGMA0 2:")
    assert doubts[1] == (
        "d_phi = 2.5000 deg in group g1 beyond MAX_BORESIGHT 1 deg: implausible for a "
        "misalignment (wrong MOUNT, image ids or observations?)"
    )
    page = _in_portuguese(render_boresight_html, None, {}, problems=doubts)
    assert "o teste global falhou com sigma0 = 3.5 &gt; MAX_SIGMA0 2: as observações" in page
    assert "d_phi = 2.5000 graus no grupo g1 além de MAX_BORESIGHT 1 graus" in page
    assert "global test failed" not in page and "beyond MAX_BORESIGHT" not in page


def test_logged_messages_render_in_portuguese():
    """A log record whose message or arguments are Messages (makecontrolchips logs
    ``"point %s: %s"`` with the chip's reason) comes out in pt_BR through ``log_text``; plain
    records are unchanged."""
    import logging

    from lidarphoto.core.photo.boresight_result import diagnose

    reason = i18n.Message("outside every image")
    rec = logging.LogRecord("lidarphoto.x", logging.WARNING, "", 0, "point %s: %s",
                            ("P7", reason), None)  # fmt: skip
    assert i18n.log_text(rec, lang="en") == rec.getMessage() == "point P7: outside every image"
    assert i18n.log_text(rec, lang="pt_BR") == "point P7: fora de todas as imagens"
    [kappa] = diagnose(["bore[NE].d_kappa"])
    rec = logging.LogRecord("lidarphoto.x", logging.INFO, "", 0, kappa, None, None)
    assert i18n.log_text(rec, lang="pt_BR").startswith("kappa do grupo 'NE' não é observável")
    from lidarphoto.core.lidar.roof_planes import extract_roof_planes

    few = extract_roof_planes(np.zeros((3, 3)) + np.arange(3.0)[:, None])
    rec = logging.LogRecord("lidarphoto.x", logging.INFO, "", 0, few.message, None, None)
    assert i18n.log_text(rec, lang="pt_BR") == (
        "nenhum plano de telhado: apenas 3 pontos candidatos (menos do que o necessário para um "
        "plano)"
    )
    plain = logging.LogRecord("lidarphoto.x", logging.INFO, "", 0, "%d of %d", (2, 5), None)
    assert i18n.log_text(plain, lang="pt_BR") == "2 of 5"
