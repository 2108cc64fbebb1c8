"""The load-time dependency check (plugin/dependencies.py)."""

from __future__ import annotations

import subprocess
import sys

from qgis.core import Qgis, QgsApplication

FAKE = "lidarphoto_no_such_module_4711"


def test_nothing_missing_in_the_test_environment():
    from lidarphoto.core.dependencies import REQUIRED_MODULES, missing_modules

    assert set(REQUIRED_MODULES) == {"laspy", "lazrs", "cv2", "scipy", "pyproj"}
    assert REQUIRED_MODULES["cv2"] == "opencv-python-headless"
    assert missing_modules() == []


def test_fake_module_is_reported():
    from lidarphoto.core.dependencies import missing_modules, pip_command

    assert missing_modules([FAKE, "cv2", "scipy"]) == [FAKE]
    cmd = pip_command([FAKE, "cv2"])
    assert " -m pip install " in cmd
    assert FAKE in cmd and "opencv-python-headless" in cmd
    import numpy

    assert f"numpy=={numpy.__version__}" in cmd  # never let pip swap QGIS's numpy


def test_report_pushes_one_message_and_logs(qgis_iface):
    from lidarphoto.plugin.dependency_check import report_missing

    logged = []

    def on_message(message, tag, level):
        logged.append((message, tag, level))

    log = QgsApplication.messageLog()
    log.messageReceived.connect(on_message)
    bar = qgis_iface.messageBar()
    bar.clear_messages()
    try:
        missing = report_missing(qgis_iface, [FAKE, "lidarphoto_other_missing_module", "numpy"])
    finally:
        log.messageReceived.disconnect(on_message)
    assert missing == [FAKE, "lidarphoto_other_missing_module"]
    warnings = bar.get_messages(Qgis.MessageLevel.Warning)
    assert len(warnings) == 1
    assert FAKE in warnings[0] and "lidarphoto_other_missing_module" in warnings[0]
    assert "pip install" in warnings[0]
    assert any(FAKE in m and level == Qgis.MessageLevel.Warning for m, _, level in logged)

    bar.clear_messages()
    assert report_missing(qgis_iface, ["numpy"]) == []
    assert bar.get_messages(Qgis.MessageLevel.Warning) == []
    assert report_missing(None, [FAKE]) == [FAKE]  # qgis_process: log only, no iface


def test_qgis_python_is_a_python_interpreter():
    """Here sys.executable is a python; the derivation from sys.exec_prefix must agree."""
    from lidarphoto.core import dependencies

    exe = dependencies.qgis_python()
    r = subprocess.run(
        [exe, "-c", "import sys; print(sys.version_info[:2])"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 0 and r.stdout.strip() == str(tuple(sys.version_info[:2]))


def test_qgis_python_when_running_inside_the_qgis_binary(monkeypatch):
    """Inside QGIS on Linux sys.executable is /usr/bin/qgis: derive python from exec_prefix."""
    from lidarphoto.core import dependencies

    monkeypatch.setattr(sys, "executable", "/usr/bin/qgis")
    monkeypatch.setattr(sys, "exec_prefix", "/usr")
    exe = dependencies.qgis_python()
    ver = f"{sys.version_info.major}.{sys.version_info.minor}"
    assert exe in (f"/usr/bin/python{ver}", "/usr/bin/python3")
    assert "qgis" not in exe


def test_missing_accelerator_is_logged_as_information_only(qgis_iface, monkeypatch):
    from lidarphoto.core import dependencies
    from lidarphoto.plugin.dependency_check import report_missing

    monkeypatch.setitem(dependencies.OPTIONAL_MODULES, FAKE, (FAKE, "something runs slower"))
    logged = []

    def on_message(message, tag, level):
        logged.append((message, level))

    log = QgsApplication.messageLog()
    log.messageReceived.connect(on_message)
    bar = qgis_iface.messageBar()
    bar.clear_messages()
    try:
        assert report_missing(qgis_iface) == []
    finally:
        log.messageReceived.disconnect(on_message)
    assert bar.get_messages(Qgis.MessageLevel.Warning) == []
    info = [m for m, level in logged if FAKE in m]
    assert len(info) == 1 and "something runs slower" in info[0] and "pip install" in info[0]
    assert all(level == Qgis.MessageLevel.Info for m, level in logged if FAKE in m)
    assert "numba" not in info[0]  # installed in the test environment
