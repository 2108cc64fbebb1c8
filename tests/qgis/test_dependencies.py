"""The load-time dependency check (plugin/dependencies.py)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys

import pytest
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


def _warnings(bar) -> list:
    return [i for i in bar.items() if i.level() == Qgis.MessageLevel.Warning]


def test_report_pushes_one_message_and_logs(qgis_iface):
    from lidarphoto.plugin.dependency_check import report_missing

    logged = []

    def on_message(message, tag, level):
        logged.append((message, tag, level))

    log = QgsApplication.messageLog()
    log.messageReceived.connect(on_message)
    bar = qgis_iface.messageBar()
    bar.clearWidgets()
    try:
        missing = report_missing(qgis_iface, [FAKE, "lidarphoto_other_missing_module", "numpy"])
    finally:
        log.messageReceived.disconnect(on_message)
    assert missing == [FAKE, "lidarphoto_other_missing_module"]
    warnings = _warnings(bar)
    assert len(warnings) == 1
    assert FAKE in warnings[0].text() and "lidarphoto_other_missing_module" in warnings[0].text()
    assert warnings[0].button.text() == "Install..."  # the dialog with the whole command
    assert any(
        FAKE in m and "pip install" in m and level == Qgis.MessageLevel.Warning
        for m, _, level in logged
    )

    bar.clearWidgets()
    assert report_missing(qgis_iface, ["numpy"]) == []
    assert _warnings(bar) == []
    assert report_missing(None, [FAKE]) == [FAKE]  # qgis_process: log only, no iface


def test_the_dialog_copies_the_command_and_shows_pip_s_failure(qgis_iface, monkeypatch):
    """The whole command for QGIS's Python, copied; Install runs pip in the task manager
    (offline here: pip fails) and shows its exit code and its own message."""
    import time

    from lidarphoto.core.dependencies import qgis_python
    from lidarphoto.plugin.dependency_dialog import DependencyDialog
    from qgis.PyQt.QtWidgets import QApplication

    monkeypatch.setenv("PIP_NO_INDEX", "1")  # no network, no local index: a quick failure
    monkeypatch.delenv("PIP_FIND_LINKS", raising=False)
    monkeypatch.delenv("PIP_INDEX_URL", raising=False)
    dialog = DependencyDialog([FAKE])
    command = dialog.command.toPlainText()
    assert command.startswith(qgis_python() + " -m pip install ") and FAKE in command
    dialog.copy_button.click()
    assert QApplication.clipboard().text() == command
    dialog.install_button.click()
    assert not dialog.install_button.isEnabled()
    t0 = time.monotonic()
    while dialog.task is not None and time.monotonic() - t0 < 120:
        QApplication.processEvents()
        time.sleep(0.05)
    assert dialog.task is None, "pip did not finish"
    assert dialog.status.text().startswith("pip failed (exit code ")
    assert FAKE in dialog.log.toPlainText()  # pip's own words name the package
    assert dialog.install_button.isEnabled()  # another try is possible


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


_PROBE = """
import json, os, sys
from lidarphoto.core.dependencies import pip_command, qgis_python
with open(os.environ["LIDARPHOTO_PROBE_OUT"], "w") as fh:
    json.dump({"executable": sys.executable, "python": qgis_python(),
               "command": pip_command(["x"])}, fh)
os._exit(0)
"""


@pytest.mark.skipif(
    not (shutil.which("xvfb-run") and os.path.exists("/usr/bin/qgis.bin")),
    reason="needs the QGIS desktop and xvfb-run",
)
def test_the_desktop_names_its_own_python_with_a_shim_first_on_path(tmp_path, plugin_dir):
    """The real QGIS desktop (under Xvfb), a pyenv-like launcher script ``python3`` first on
    PATH: the embedded Python's sys.executable is that script, but the command names the
    interpreter QGIS runs."""
    shim = tmp_path / "shims"
    shim.mkdir()
    (shim / "python3").write_text('#!/bin/sh\nexec /usr/bin/python3 "$@"\n')
    (shim / "python3").chmod(0o755)
    probe, out = tmp_path / "probe.py", tmp_path / "out.json"
    probe.write_text(_PROBE)
    env = {
        **os.environ,
        "PATH": f"{shim}:{os.environ['PATH']}",
        "PYTHONPATH": str(plugin_dir),
        "LIDARPHOTO_PROBE_OUT": str(out),
        "HOME": str(tmp_path),
    }
    env.pop("QT_QPA_PLATFORM", None)
    subprocess.run(
        [
            "xvfb-run",
            "-a",
            "/usr/bin/qgis.bin",
            "--nologo",
            "--noversioncheck",
            "--noplugins",
            "--code",
            str(probe),
        ],
        env=env,
        timeout=180,
        capture_output=True,
    )
    got = json.loads(out.read_text())
    assert got["executable"] == str(shim / "python3")  # what the embedded Python believes
    ver = f"{sys.version_info.major}.{sys.version_info.minor}"
    assert got["python"] in (f"/usr/bin/python{ver}", "/usr/bin/python3"), got
    assert got["command"].startswith(got["python"] + " -m pip install --user ")
