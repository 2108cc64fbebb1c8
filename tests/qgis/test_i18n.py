"""Translation: QGIS in Brazilian Portuguese shows the toolbox, help and dock in Portuguese,
the catalogue is complete and up to date with the code (``make i18n``)."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from qgis_helpers import PLUGIN, QGIS_PROCESS, ROOT

TS = ROOT / "i18n" / "lidarphoto_pt_BR.ts"
QM = ROOT / "i18n" / "lidarphoto_pt_BR.qm"
I18N_SCRIPT = ROOT / "scripts" / "i18n.py"
HAVE_TOOLS = shutil.which("pylupdate5") is not None and (
    shutil.which("lrelease") is not None or Path("/usr/lib/qt5/bin/lrelease").exists()
)
needs_tools = pytest.mark.skipif(
    not HAVE_TOOLS, reason="pylupdate5/lrelease missing (apt: pyqt5-dev-tools qttools5-dev-tools)"
)
_PLACEHOLDER = re.compile(r"\{[^{}]*\}")


@pytest.fixture(scope="module")
def compiled_qm() -> None:
    """Build i18n/*.qm from the .ts (not committed; `make i18n` and `make package` do it too)."""
    if not HAVE_TOOLS:
        pytest.skip("lrelease missing (apt: qttools5-dev-tools)")
    r = subprocess.run(
        [sys.executable, str(I18N_SCRIPT), "--qm", str(QM.parent)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0 and QM.is_file(), r.stdout + r.stderr


def _messages():
    root = ET.parse(TS).getroot()
    assert root.get("language") == "pt_BR"
    for ctx in root.iter("context"):
        for m in ctx.iter("message"):
            yield ctx.findtext("name"), m.findtext("source"), m.find("translation")


def test_catalogue_is_complete():
    """Every message has a finished, non-empty translation that keeps the source's {}
    placeholders and HTML tags (a missing one would break .format() or the layout)."""
    count = 0
    for ctx, source, tr in _messages():
        if tr.get("type") == "vanished":
            continue
        count += 1
        where = f"[{ctx}] {source[:80]!r}"
        assert tr.get("type") != "unfinished", f"untranslated: {where}"
        assert (tr.text or "").strip(), f"empty translation: {where}"
        assert sorted(_PLACEHOLDER.findall(source)) == sorted(_PLACEHOLDER.findall(tr.text)), (
            f"placeholders differ: {where}"
        )
        tags = re.compile(r"</?[a-z]+>")
        assert sorted(tags.findall(source)) == sorted(tags.findall(tr.text)), f"tags: {where}"
    assert count > 700


@needs_tools
def test_catalogue_is_up_to_date_with_the_code():
    """Re-running the extraction adds no string and drops none: a new algorithm, label or
    message fails here until `make i18n` is run and the new strings are translated."""
    r = subprocess.run(
        [sys.executable, str(I18N_SCRIPT), "--check"], capture_output=True, text=True, timeout=300
    )
    assert r.returncode == 0, "run `make i18n`, then translate:\n" + r.stdout[-4000:] + r.stderr


def test_every_algorithm_string_is_in_the_catalogue():
    """The spec texts of every registered algorithm are messages of the catalogue (context
    lidarphoto:<algorithm>), so the toolbox can show them translated."""
    from lidarphoto.core.jobs import ALGORITHMS
    from lidarphoto.core.jobs.translate import context_of, spec_messages

    known = {(c, s) for c, s, _ in _messages()}
    for job in ALGORITHMS:
        for text in spec_messages(job.SPEC):
            assert (context_of(job.SPEC), text) in known, (job.SPEC.name, text[:80])


@needs_tools
def test_qgis_process_in_portuguese(qp_env, compiled_qm):
    """qgis_process (no GUI: the provider installs the translator) with the QGIS user locale
    pt_BR prints the algorithm's name, parameters and help in Portuguese."""
    ini = Path(qp_env["QGIS_CUSTOM_CONFIG_PATH"]) / "profiles" / "default" / "QGIS" / "QGIS3.ini"
    ini.write_text(
        ini.read_text(encoding="utf-8") + "\n[locale]\noverrideFlag=true\nuserLocale=pt_BR\n",
        encoding="utf-8",
    )
    r = subprocess.run(
        [QGIS_PROCESS, "help", "lidarphoto:groundfilter"],
        env=qp_env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    out = r.stdout
    for text in (
        "Filtro de terreno (SMRF, PMF, simulação de tecido)",  # displayName
        "Separa o terreno dos objetos",  # help (description)
        "Parâmetros",  # the help's fixed words
        "Tamanho da célula do SMRF",  # a parameter label
        "Nuvem de pontos classificada",  # an output
    ):
        assert text in out, text
    assert "Separates ground from objects" not in out


@needs_tools
def test_report_follows_the_qgis_language(qp_env, compiled_qm, tmp_path):
    """qgis_process in pt_BR writes the accuracy report (HTML) in Portuguese."""
    ini = Path(qp_env["QGIS_CUSTOM_CONFIG_PATH"]) / "profiles" / "default" / "QGIS" / "QGIS3.ini"
    ini.write_text(
        ini.read_text(encoding="utf-8") + "\n[locale]\noverrideFlag=true\nuserLocale=pt_BR\n",
        encoding="utf-8",
    )
    rows = ["id,e,n,h,e_ref,n_ref,h_ref"]
    for k in range(8):
        e, n, h = 500000.0 + 37 * k, 7450000.0 + 53 * k, 10.0 + k
        rows.append(f"P{k},{e + 0.03 * (-1) ** k},{n - 0.02 * (k % 3)},{h + 0.05},{e},{n},{h}")
    table = tmp_path / "check.csv"
    table.write_text("\n".join(rows) + "\n", encoding="utf-8")
    html = tmp_path / "report.html"
    r = subprocess.run(
        [QGIS_PROCESS, "run", "lidarphoto:accuracyreport", "--", f"INPUT={table}",
         "CRS=EPSG:31983", f"OUTPUT_HTML={html}", f"OUTPUT={tmp_path / 'cp.gpkg'}"],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    page = html.read_text(encoding="utf-8")
    assert '<html lang="pt-BR">' in page
    assert "<h2>Resumo</h2>" in page and "<h2>Estatísticas</h2>" in page
    assert "<h2>Summary</h2>" not in page


def test_provider_and_dock_in_portuguese(compiled_qm, provider, qgis_iface, tmp_path):
    """With the pt_BR translator: algorithm names, groups, help, parameter labels, the
    dock's tabs, help and observation table, the plugin's menu; and back to English."""
    from lidarphoto.core import i18n as core_i18n
    from lidarphoto.plugin.image_dock import ImagePickingDock
    from lidarphoto.processing_provider.i18n import install_translator, remove_translator
    from qgis.core import QgsApplication

    assert install_translator("pt_BR") == "pt_BR"
    try:
        assert core_i18n.current_language() == "pt_BR"
        registry = QgsApplication.processingRegistry()
        alg = registry.algorithmById("lidarphoto:bundleadjustment").create()
        assert alg.displayName() == "Ajustamento por feixes de raios com autocalibração"
        assert alg.group() == "Aerotriangulação"
        help_html = alg.shortHelpString()
        assert "<h3>Parâmetros</h3>" in help_html and "Referências" in help_html
        assert "pontos-objeto" in help_html and "Bundle adjustment of a block" not in help_html
        assert alg.parameterDefinition("DATUM").description() == "Referencial (datum)"
        boresight = registry.algorithmById("lidarphoto:boresightcalibration").create()
        assert boresight.displayName() == "Calibração de boresight"
        every = [a for a in registry.algorithms() if a.provider().id() == PLUGIN]
        english = {a.name(): a.displayName() for a in every if a.displayName() == a.spec.title}
        assert not english, f"algorithms left in English: {english}"

        dock = ImagePickingDock(qgis_iface, None)
        try:
            tabs = [dock.tabs.tabText(i) for i in range(dock.tabs.count())]
            assert tabs == ["Projeto", "Calibração", "Resseção", "Feixes", "Ajuda"]
            help_label = dock.tabs.widget(tabs.index("Ajuda"))
            assert help_label.text().startswith("<b>Medição</b>")
            model = dock.table.model()
            headers = [model.headerData(c, 1) for c in range(model.columnCount())]
            assert headers[:3] == ["imagem", "ponto", "tipo"]
            assert dock.windowTitle() == "Medição de Pontos na Imagem"
        finally:
            dock.view.shutdown()
            dock.deleteLater()
    finally:
        remove_translator()
    alg = QgsApplication.processingRegistry().algorithmById("lidarphoto:bundleadjustment")
    assert alg.create().displayName() == "Bundle adjustment with self-calibration"
    assert core_i18n.current_language() == "en"


def test_plugin_messages_in_portuguese(compiled_qm, tmp_path):
    """The picking dock's image messages (the Qt-free image source's errors, the overview
    task's) follow QGIS's language; English again without the translator."""
    from lidarphoto.plugin.image_source import ImageSource, ImageSourceError, error_text
    from lidarphoto.processing_provider.i18n import install_translator, remove_translator
    from qgis.PyQt.QtCore import QCoreApplication

    missing = tmp_path / "none.tif"
    with pytest.raises(ImageSourceError) as info:
        ImageSource(missing)
    assert str(info.value) == f"{missing}: the image file does not exist"
    assert install_translator("pt_BR") == "pt_BR"
    try:
        assert error_text(info.value) == f"{missing}: o arquivo de imagem não existe"
        text = QCoreApplication.translate("OverviewTask", "{path}: overview build cancelled")
        assert text.format(path="a.tif") == "a.tif: construção das visões gerais cancelada"
    finally:
        remove_translator()
    assert error_text(info.value) == f"{missing}: the image file does not exist"


def test_logged_messages_reach_the_feedback_in_portuguese(compiled_qm):
    """The Processing log bridge (forward_logging) shows a core log record whose arguments
    are Messages in QGIS's language: makecontrolchips' "point %s: %s" with the chip's reason,
    createlcps' rejection summary; plain records unchanged; English without the translator."""
    import logging

    from lidarphoto.core.lidar.control import REJECT_SUPPORT, Rejection, rejection_summary
    from lidarphoto.core.photo.control_location import _t as mark
    from lidarphoto.processing_provider.base import forward_logging
    from lidarphoto.processing_provider.i18n import install_translator, remove_translator
    from qgis.core import QgsProcessingFeedback

    class Feedback(QgsProcessingFeedback):
        def __init__(self):
            super().__init__()
            self.lines = []

        def pushInfo(self, text):
            self.lines.append(("info", text))

        def pushWarning(self, text):
            self.lines.append(("warning", text))

    log = logging.getLogger("lidarphoto.core.jobs.test")

    def run():
        feedback = Feedback()
        with forward_logging(feedback):
            log.warning("point %s: %s", "P7", mark("outside every image"))
            log.info(rejection_summary([Rejection((1, 2, 3), "x", REJECT_SUPPORT)] * 2))
            log.info("%d of %d", 2, 5)
        return feedback.lines

    assert install_translator("pt_BR") == "pt_BR"
    try:
        lines = run()
    finally:
        remove_translator()
    assert lines == [
        ("warning", "point P7: fora de todas as imagens"),
        ("info", "2 candidatos rejeitados: 2 interseção longe dos pontos de um plano"),
        ("info", "2 of 5"),
    ]
    assert run()[:2] == [
        ("warning", "point P7: outside every image"),
        ("info", "2 candidates rejected: 2 intersection far from a plane's points"),
    ]


def test_a_checkout_without_the_compiled_catalogue_still_speaks_portuguese(
    qgis_iface, tmp_path, monkeypatch
):
    """A plugin folder linked from a checkout has only the .ts (the .qm is built by `make
    package`): the translator reads the .ts; the dock's overlay toggles are translated."""
    import shutil

    from lidarphoto.core import i18n as core_i18n
    from lidarphoto.plugin.image_dock import ImagePickingDock
    from lidarphoto.processing_provider import i18n as qt_i18n
    from qgis.PyQt.QtCore import QCoreApplication

    folder = tmp_path / "i18n"
    folder.mkdir()
    shutil.copy2(ROOT / "i18n" / "lidarphoto_pt_BR.ts", folder)
    monkeypatch.setattr(core_i18n, "I18N_DIR", folder)
    core_i18n.catalogue.cache_clear()
    try:
        assert qt_i18n.install_translator("pt_BR") == "pt_BR"
        text = QCoreApplication.translate("OverviewTask", "{path}: overview build cancelled")
        assert text.format(path="a.tif") == "a.tif: construção das visões gerais cancelada"
        dock = ImagePickingDock(qgis_iface, None)
        try:
            toggles = [box.text() for box in dock.viewer.overlay_checks.values()]
            assert toggles == ["planos", "linhas", "LCPs", "resíduos", "observações", "previsões"]
        finally:
            dock.view.shutdown()
            dock.deleteLater()
    finally:
        qt_i18n.remove_translator()
        core_i18n.catalogue.cache_clear()
