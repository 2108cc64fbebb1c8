#!/usr/bin/env python3
"""Update the translation catalogues ``i18n/lidarphoto_<lang>.ts`` from the code (``make i18n``).

    python3 scripts/i18n.py            update every .ts, then compile the .qm files (lrelease)
    python3 scripts/i18n.py --check    exit 1 and list the messages when a .ts lacks a string
                                       of the code or holds one the code no longer has
    python3 scripts/i18n.py --qm DIR   only compile the .qm files into DIR (scripts/package.sh)

Where the messages come from:
- the Qt side (plugin/, processing_provider/): Qt's ``pylupdate5`` (Debian pyqt5-dev-tools)
  collects ``self.tr("...")`` (context: the class) and ``QCoreApplication.translate("ctx",
  "...")``;
- the algorithms' specs (core/jobs): pylupdate cannot see them, so every job's texts are
  listed by ``core.jobs.translate.spec_messages`` in the context ``lidarphoto:<algorithm>``;
- the rest of the core (the help's fixed words, the HTML reports, the sentences the science
  builds with numbers) and the plugin's Qt-free modules: calls ``t("...")``, ``tr("...")``,
  ``_t("...")`` or ``_tr("...")`` with a literal, in modules that define
  ``TR_CONTEXT = "<context>"`` or import it (``from .html_table import TR_CONTEXT``).

Existing translations are kept; a new message is added as unfinished; a message the code no
longer has is kept as ``vanished`` only if it was translated (a hint for its successor).
Messages carry no line numbers, so moving code does not change the .ts.
"""

from __future__ import annotations

import argparse
import ast
import os
import re
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
I18N = ROOT / "i18n"
QT_SOURCES = ("plugin", "processing_provider")
CORE = ROOT / "core"
_TRAILING_COMMA = re.compile(r",(\s*)\)")


def _pylupdate_messages() -> list[tuple[str, str]]:
    exe = shutil.which("pylupdate5")
    if exe is None:
        sys.exit("i18n.py: pylupdate5 not found (Debian: apt-get install pyqt5-dev-tools)")
    files = sorted(p.relative_to(ROOT) for d in QT_SOURCES for p in (ROOT / d).rglob("*.py"))
    with tempfile.TemporaryDirectory() as tmp:
        # pylupdate5 drops a call whose last argument ends with a comma (ruff's magic trailing
        # comma on a split call): it reads copies without them (only the messages matter)
        for rel in files:
            copy = Path(tmp, "src", rel)
            copy.parent.mkdir(parents=True, exist_ok=True)
            text = (ROOT / rel).read_text(encoding="utf-8")
            copy.write_text(_TRAILING_COMMA.sub(r"\1)", text), encoding="utf-8")
        ts = Path(tmp) / "qt.ts"
        r = subprocess.run(
            [exe, "-noobsolete", *map(str, files), "-ts", str(ts)],
            cwd=Path(tmp, "src"),
            capture_output=True,
            text=True,
            env={**os.environ, "PYTHONWARNINGS": "ignore"},
        )
        if r.returncode != 0 or not ts.is_file():
            sys.exit(f"i18n.py: pylupdate5 failed:\n{r.stdout}{r.stderr}")
        out = []
        for ctx in ET.parse(ts).getroot().iter("context"):
            name = ctx.findtext("name", "")
            out += [(name, m.findtext("source", "")) for m in ctx.iter("message")]
        return out


def _spec_messages() -> list[tuple[str, str]]:
    """The texts of every job's spec (imports the package through a temporary symlink, so
    that the script runs from any check-out folder name)."""
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "lidarphoto").symlink_to(ROOT, target_is_directory=True)
        sys.path.insert(0, tmp)
        try:
            from lidarphoto.core.jobs import ALGORITHMS
            from lidarphoto.core.jobs.translate import context_of, spec_messages

            return [(context_of(j.SPEC), t) for j in ALGORITHMS for t in spec_messages(j.SPEC)]
        finally:
            sys.path.remove(tmp)


def _module_context(path: Path) -> str | None:
    """The TR_CONTEXT a module assigns, None when it has none."""
    if not path.is_file():
        return None
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if (
            isinstance(node, ast.Assign)
            and any(isinstance(t, ast.Name) and t.id == "TR_CONTEXT" for t in node.targets)
            and isinstance(node.value, ast.Constant)
        ):
            return node.value.value
    return None


def _core_messages() -> list[tuple[str, str]]:
    """``t("...")``/``tr("...")`` literals of core modules (and of the plugin's Qt-free ones,
    e.g. plugin/image_source.py) that define ``TR_CONTEXT``."""
    out = []
    for path in sorted([*CORE.rglob("*.py"), *(ROOT / "plugin").rglob("*.py")]):
        if "simulation" in path.parts:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        context = None
        for node in tree.body:
            if isinstance(node, ast.ImportFrom) and any(
                a.name == "TR_CONTEXT" for a in node.names
            ):  # the context of the module it comes from (a sibling: ``from .x import``)
                context = _module_context(path.parent / f"{node.module}.py")
            if (
                isinstance(node, ast.Assign)
                and any(isinstance(t, ast.Name) and t.id == "TR_CONTEXT" for t in node.targets)
                and isinstance(node.value, ast.Constant)
            ):
                context = node.value.value
        if context is None:
            continue
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Call)
                and isinstance(node.func, ast.Name)
                and node.func.id in ("t", "tr", "_t", "_tr")
                and node.args
                and isinstance(node.args[0], ast.Constant)
                and isinstance(node.args[0].value, str)
            ):
                out.append((context, node.args[0].value))
    return out


def code_messages() -> list[tuple[str, str]]:
    """Every (context, source) of the code, in a stable order, without repeats."""
    seen, out = set(), []
    for key in _pylupdate_messages() + _spec_messages() + _core_messages():
        if key[1] and key not in seen:
            seen.add(key)
            out.append(key)
    return out


def read_ts(path: Path) -> tuple[str, dict[tuple[str, str], tuple[str, str]]]:
    """(language, {(context, source): (translation, type)}) of a .ts file."""
    root = ET.parse(path).getroot()
    found = {}
    for ctx in root.iter("context"):
        name = ctx.findtext("name", "")
        for m in ctx.iter("message"):
            tr = m.find("translation")
            text = "" if tr is None else (tr.text or "")
            kind = "" if tr is None else tr.get("type", "")
            found[(name, m.findtext("source", ""))] = (text, kind)
    return root.get("language", path.stem.split("_", 1)[1]), found


def merged(messages, old: dict) -> dict[tuple[str, str], tuple[str, str]]:
    """The new catalogue: the code's messages with their old translations, plus the old
    translated messages the code lost (vanished)."""
    out = {}
    for key in messages:
        text, kind = old.get(key, ("", "unfinished"))
        if kind in ("vanished", "obsolete"):
            kind = "unfinished"  # it came back: ask for a review
        out[key] = (text, "unfinished" if not text else kind)
    for key, (text, _kind) in old.items():
        if key not in out and text:
            out[key] = (text, "vanished")
    return out


def write_ts(path: Path, language: str, catalogue: dict) -> None:
    root = ET.Element("TS", version="2.1", language=language)
    by_context: dict[str, list] = {}
    for (ctx, source), value in catalogue.items():
        by_context.setdefault(ctx, []).append((source, value))
    for ctx in sorted(by_context):
        c = ET.SubElement(root, "context")
        ET.SubElement(c, "name").text = ctx
        for source, (text, kind) in by_context[ctx]:
            m = ET.SubElement(c, "message")
            ET.SubElement(m, "source").text = source
            tr = ET.SubElement(m, "translation")
            if kind:
                tr.set("type", kind)
            tr.text = text or None
    ET.indent(root, space="    ")
    body = ET.tostring(root, encoding="unicode")
    path.write_text(
        '<?xml version="1.0" encoding="utf-8"?>\n<!DOCTYPE TS>\n' + body + "\n", encoding="utf-8"
    )


def compile_qm(out_dir: Path) -> list[Path]:
    """lrelease every .ts into ``out_dir``; returns the .qm files."""
    exe = shutil.which("lrelease") or "/usr/lib/qt5/bin/lrelease"
    if not Path(exe).exists() and shutil.which(exe) is None:
        sys.exit("i18n.py: lrelease not found (Debian: apt-get install qttools5-dev-tools)")
    out_dir.mkdir(parents=True, exist_ok=True)
    done = []
    for ts in sorted(I18N.glob("lidarphoto_*.ts")):
        qm = out_dir / ts.with_suffix(".qm").name
        r = subprocess.run(
            [exe, "-silent", str(ts), "-qm", str(qm)], capture_output=True, text=True
        )
        if r.returncode != 0 or not qm.is_file():
            sys.exit(f"i18n.py: lrelease {ts.name} failed:\n{r.stdout}{r.stderr}")
        done.append(qm)
    return done


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="report, change nothing")
    ap.add_argument("--qm", metavar="DIR", help="only compile the .qm files into DIR")
    args = ap.parse_args(argv)
    if args.qm:
        for qm in compile_qm(Path(args.qm)):
            print(qm)
        return 0
    messages = code_messages()
    status = 0
    for ts in sorted(I18N.glob("lidarphoto_*.ts")):
        language, old = read_ts(ts)
        new = merged(messages, old)
        live_old = {k for k, (_, kind) in old.items() if kind not in ("vanished", "obsolete")}
        added = [k for k in messages if k not in live_old]
        gone = sorted(live_old - set(messages))
        if args.check:
            if added or gone:
                status = 1
                print(f"{ts.relative_to(ROOT)} is out of date: run `make i18n`, then translate")
                for ctx, source in added:
                    print(f"  new  [{ctx}] {source[:100]!r}")
                for ctx, source in gone:
                    print(f"  gone [{ctx}] {source[:100]!r}")
            continue
        write_ts(ts, language, new)
        todo = sum(1 for _, kind in new.values() if kind == "unfinished")
        print(f"{ts.relative_to(ROOT)}: {len(messages)} messages, {len(added)} new, "
              f"{len(gone)} gone, {todo} to translate")  # fmt: skip
    if not args.check:
        for qm in compile_qm(I18N):
            print(qm.relative_to(ROOT))
    return status


if __name__ == "__main__":
    sys.exit(main())
