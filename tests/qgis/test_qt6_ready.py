"""QGIS 4 / Qt6 readiness, checked statically (Debian has no QGIS 4 yet): the plugin and the
provider use none of the Qt5-only API that QGIS's migration script
(scripts/pyqt5_to_pyqt6/pyqt5_to_pyqt6.py in qgis/QGIS) rewrites or that PyQt6 removed.

What is checked, in plugin/, processing_provider/ and __init__.py (see ../shared/STYLE.md,
"QGIS 3.22 -> QGIS 4"):
- every Qt and QGIS enum value is reached through its enum class (``Qt.AlignmentFlag.AlignLeft``,
  ``QgsWkbTypes.Type.Point``): the attribute chains are resolved on the running PyQt5/QGIS, and a
  class attribute that is an enum *value* is an unscoped enum, which PyQt6 refuses;
- no ``exec_()``/``print_()``, ``QRegExp``, ``QDesktopWidget``, ``qApp``, ``QString``/``QVariant()``
  null values, ``QFontMetrics.width``, ``activated[str]`` overloads, ``.delta()`` of wheel events,
  ``resources_rc``;
- Qt is imported only through ``qgis.PyQt`` (never PyQt5/PyQt6/sip directly), and widgets only
  from ``QtWidgets`` (PyQt6 has no widgets in QtGui);
- no ``self.tr(f"...")``: a formatted string is never found in the translations.
"""

from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest
from qgis_helpers import ROOT

FILES = sorted(
    [*ROOT.joinpath("plugin").rglob("*.py"), *ROOT.joinpath("processing_provider").rglob("*.py")]
) + [ROOT / "__init__.py"]
#: text patterns of Qt5-only API (PyQt6 removed them; pyqt5_to_pyqt6.py rewrites most)
REMOVED = {
    r"\.exec_\(": "exec_() -> exec()",
    r"\.print_\(": "print_() -> print()",
    r"\bQRegExp\b": "QRegExp -> QRegularExpression",
    r"\bQDesktopWidget\b": "QDesktopWidget -> QScreen",
    r"\bqApp\b": "qApp -> QApplication.instance()",
    r"\bQString\b": "QString does not exist in PyQt",
    r"QVariant\(\)": "QVariant() null -> NULL",
    r"\bQFontMetrics(F)?\b.*\.width\(": "QFontMetrics.width -> horizontalAdvance",
    r"\[str\]\.connect": "signal overloads by type ([str]) are gone",
    r"\.delta\(\)": "QWheelEvent.delta() -> angleDelta()",
    r"\bresources_rc\b": "compiled resources are not built for Qt6",
    r"^\s*(from|import)\s+(PyQt5|PyQt6|sip)\b": "import Qt through qgis.PyQt",
    r"\btr\(\s*f[\"']": "tr(f'...'): a formatted string has no translation",
}
#: (file, class) allowed to use enum values unscoped: QgsField's QVariant.<Type> is needed on
#: 3.22 and patched to QMetaType.Type by Qt6 builds of QGIS (STYLE.md section 5, rule 4)
ALLOWED = {("processing_provider/compat.py", "QVariant")}
WIDGETS_NOT_IN_QTGUI = re.compile(
    r"from qgis\.PyQt\.QtGui import[^\n]*"
    r"\bQ(Widget|Dialog|Label|PushButton|LineEdit|ComboBox|Menu|MessageBox|ToolButton)\b"
)


def _imports(tree: ast.Module) -> dict[str, object]:
    """Names bound by ``from qgis... import X`` (resolved to the objects)."""
    names = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("qgis."):
            module = importlib.import_module(node.module)
            for alias in node.names:
                obj = getattr(module, alias.name, None)
                if obj is not None:
                    names[alias.asname or alias.name] = obj
    return names


def _is_enum_value(value: object) -> bool:
    return (
        isinstance(value, int)
        and not isinstance(value, (bool, type))
        and type(value).__module__ != "builtins"
    )


def unscoped_enums(path: Path) -> list[str]:
    """``Class.Value`` where Value is an enum value of a Qt or QGIS class (not ``Class.Enum``)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names = _imports(tree)
    rel = str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else path.name
    found = []
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)):
            continue
        owner = names.get(node.value.id)
        if (rel, node.value.id) in ALLOWED or not isinstance(owner, type):
            continue
        try:
            value = getattr(owner, node.attr)
        except AttributeError:
            continue
        if _is_enum_value(value):
            scoped = type(value).__name__
            found.append(
                f"{rel}:{node.lineno}: {node.value.id}.{node.attr} -> "
                f"{node.value.id}.{scoped}.{node.attr}"
            )
    return found


def test_the_enum_check_sees_an_unscoped_enum(tmp_path):
    """The checker itself: Qt.AlignLeft is flagged, Qt.AlignmentFlag.AlignLeft is not."""
    probe = tmp_path / "probe.py"
    probe.write_text(
        "from qgis.PyQt.QtCore import Qt\nfrom qgis.core import QgsWkbTypes\n"
        "a = Qt.AlignLeft\nb = Qt.AlignmentFlag.AlignLeft\nc = QgsWkbTypes.Point\n"
        "d = QgsWkbTypes.Type.Point\n",
        encoding="utf-8",
    )
    found = unscoped_enums(probe)
    assert len(found) == 2
    assert "Qt.AlignLeft -> Qt.AlignmentFlag.AlignLeft" in found[0]
    assert "QgsWkbTypes.Point -> QgsWkbTypes.Type.Point" in found[1]


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_unscoped_enum(path):
    assert unscoped_enums(path) == []


def test_no_qt5_only_api():
    problems = []
    for path in FILES:
        text = path.read_text(encoding="utf-8")
        for k, line in enumerate(text.splitlines(), 1):
            for pattern, why in REMOVED.items():
                if re.search(pattern, line):
                    problems.append(f"{path.relative_to(ROOT)}:{k}: {why}: {line.strip()}")
        for m in WIDGETS_NOT_IN_QTGUI.finditer(text):
            problems.append(f"{path.relative_to(ROOT)}: widgets come from QtWidgets: {m[0]}")
    assert problems == []


def test_metadata_states_the_qt6_check():
    """metadata.txt claims QGIS 4 / Qt6 support only together with this check."""
    text = (ROOT / "metadata.txt").read_text(encoding="utf-8")
    assert "supportsQt6=True" in text
    assert re.search(r"^qgisMaximumVersion=4\.\d+$", text, re.M)
    assert "tests/qgis/test_qt6_ready.py" in text
