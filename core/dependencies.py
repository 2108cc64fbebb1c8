"""Which third-party packages of the core are missing, and the pip command that installs them.

Qt-free: the plugin shows these messages at load time (one message-bar warning plus a log
entry) and every algorithm's ``canExecute`` uses them; nothing here raises.
"""

from __future__ import annotations

import importlib
import os
import shlex
import sys
import sysconfig
from collections.abc import Iterable, Sequence

from .i18n import translator  # standard library only, like this module

#: translation context of the messages below (``make i18n`` collects the ``t("...")`` calls)
TR_CONTEXT = "Messages"


def t(text: str) -> str:
    """``text`` in the language set by :func:`core.i18n.set_language`."""
    return translator(TR_CONTEXT)(text)


#: import name -> pip requirement, in the order they are reported.
REQUIRED_MODULES: dict[str, str] = {
    "laspy": "laspy",
    "lazrs": "lazrs",
    "cv2": "opencv-python-headless",
    "scipy": "scipy",
    "pyproj": "pyproj",
}

#: optional packages: import name -> (pip requirement, what is slower or missing without it).
OPTIONAL_MODULES: dict[str, tuple[str, str]] = {
    "numba": (
        "numba",
        "ray casting on the DSM (monoplotting) runs 2-3x slower, orthophotos "
        "about 2.5x, roof planes about 3.5x",
    ),
    "distributed": (
        "distributed",
        "the LiDAR block algorithm (lidarblock, tiles on dask) cannot run",
    ),
}


def missing_modules(modules: Iterable[str] | None = None) -> list[str]:
    """Return the names in ``modules`` (default: REQUIRED_MODULES) that fail to import."""
    names = list(REQUIRED_MODULES) if modules is None else list(modules)
    missing = []
    for name in names:
        try:
            importlib.import_module(name)
        except Exception:  # ImportError, but also broken binaries (numpy ABI, missing .so)
            missing.append(name)
    return missing


def pip_requirements(modules: Sequence[str]) -> list[str]:
    """Pip requirement names for import names (unknown names are passed through)."""
    seen: list[str] = []
    for name in modules:
        req = REQUIRED_MODULES.get(name, name)
        if req not in seen:
            seen.append(req)
    return seen


def _is_this_python(path: str) -> bool:
    """Whether ``path`` is an interpreter of the Python that runs: a binary (not a launcher
    script such as a pyenv shim) in this installation's binary folder, or in this venv's
    (another venv's ``python3``, first on PATH, would install where QGIS does not look)."""
    if not path or not os.path.isfile(path):
        return False
    try:
        with open(path, "rb") as fh:
            if fh.read(2) == b"#!":
                return False
    except OSError:
        return False
    here = os.path.realpath(os.path.dirname(os.path.abspath(path)))
    homes = (sys.exec_prefix, sys.base_exec_prefix)
    if sys.platform == "win32":
        folders = {os.path.realpath(h) for h in homes}
    else:
        folders = {os.path.realpath(os.path.join(h, "bin")) for h in homes}
    return here in folders


def _interpreter_candidates() -> list[str]:
    """Where this installation keeps its interpreter, most specific first."""
    ver = f"{sys.version_info.major}.{sys.version_info.minor}"
    prefixes = dict.fromkeys((sys.exec_prefix, sys.base_exec_prefix))  # a venv first
    if sys.platform == "win32":  # OSGeo4W / standalone installer: <prefix>/python.exe
        return [os.path.join(p, n) for p in prefixes for n in ("python.exe", "python3.exe")]
    # Linux packages (/usr), macOS QGIS.app (.../Contents/MacOS or Frameworks)
    names = (f"python{ver}", "python3", "python")
    return [os.path.join(p, "bin", n) for p in prefixes for n in names]


def qgis_python() -> str:
    """Path of the Python interpreter QGIS embeds.

    Inside QGIS, ``sys.executable`` is QGIS itself, or what an embedded Python found first
    on PATH under the name ``python3`` (a pyenv shim, another venv): it is trusted only when
    it is an interpreter of the installation that runs (:func:`_is_this_python`); else the
    interpreter is derived from ``sys.exec_prefix`` / ``sys.base_exec_prefix``.
    """
    exe = sys.executable or ""
    if os.path.basename(exe).lower().startswith("python") and _is_this_python(exe):
        return exe
    candidates = _interpreter_candidates()
    for path in candidates:
        if os.path.isfile(path) and (sys.platform == "win32" or _is_this_python(path)):
            return path
    return candidates[0]


def _externally_managed() -> bool:
    """True for a PEP 668 system Python (Debian/Ubuntu >= 12/23.04), where pip needs a flag."""
    stdlib = sysconfig.get_paths().get("stdlib", "")
    return bool(stdlib) and os.path.isfile(os.path.join(stdlib, "EXTERNALLY-MANAGED"))


def pip_argv(modules: Sequence[str]) -> list[str]:
    """The pip call that installs ``modules`` into QGIS's Python, as a program and its
    arguments (what the plugin's Install button runs).

    numpy is pinned to the version QGIS already uses, so pip cannot replace it by an
    ABI-incompatible one (numpy 2 breaks GDAL's and QGIS's compiled numpy bindings).
    """
    python = qgis_python()
    args = [python, "-m", "pip", "install"]
    if sys.platform != "win32" and sys.prefix == sys.base_prefix:  # a venv takes no --user
        args.append("--user")
        if _externally_managed():
            args.append("--break-system-packages")
    args += pip_requirements(modules)
    try:
        import numpy

        args.append(f"numpy=={numpy.__version__}")
    except Exception:
        pass
    return args


def pip_command(modules: Sequence[str]) -> str:
    """:func:`pip_argv` as one shell command, quoted for this platform's shell."""
    args = pip_argv(modules)
    if sys.platform == "win32":
        return " ".join(f'"{a}"' if " " in a else a for a in args)
    return " ".join(shlex.quote(a) for a in args)


def missing_message(modules: Sequence[str]) -> str:
    """The user-facing text for missing modules (in the language of :mod:`core.i18n`)."""
    return t(
        "Missing Python packages: {names}. The LiDAR Photogrammetry algorithms need them; "
        "install them into QGIS's Python and restart QGIS: {cmd}"
    ).format(names=", ".join(pip_requirements(modules)), cmd=pip_command(modules))


def optional_message(modules: Sequence[str]) -> str:
    """The log text for missing optional accelerators."""
    effects = "; ".join(OPTIONAL_MODULES[m][1] for m in modules if m in OPTIONAL_MODULES)
    reqs = [OPTIONAL_MODULES[m][0] if m in OPTIONAL_MODULES else m for m in modules]
    return t(
        "Optional Python packages not installed: {names} ({effects}). To install: {cmd}"
    ).format(names=", ".join(reqs), effects=effects, cmd=pip_command(reqs))
