"""The code's pointers into the documentation lead somewhere: every ``docs/<file>.md`` it
cites exists, every ``docs/<file>.md, "Section"`` has that heading, and no module cites the
design notes outside the repository (``DESIGN.md``: their content is docs/conventions.md)."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CODE = [p for d in ("core", "processing_provider", "plugin") for p in (ROOT / d).rglob("*.py")]
#: Modules still citing the design notes outside the repository (none: the bundle's mount
#: corrections cite docs/conventions.md "Rotations" since its split).
DESIGN_CITED_UNTIL_SPLIT: set[str] = set()


def _text(path: Path) -> str:
    """The file with comment and docstring line breaks joined (a pointer may span two)."""
    return re.sub(r"\s*\n\s*(?:#:?\s*)?", " ", path.read_text(encoding="utf-8"))


def test_every_cited_document_and_section_exists():
    missing = []
    for path in CODE:
        for doc, section in re.findall(r"docs/([a-z_]+\.md)(?:,\s*\"([^\"]+)\")?", _text(path)):
            target = ROOT / "docs" / doc
            if not target.is_file():
                missing.append((path.relative_to(ROOT).as_posix(), doc))
            elif section and not re.search(rf"(?m)^#+ {re.escape(section)}",
                                           target.read_text(encoding="utf-8")):  # fmt: skip
                missing.append((path.relative_to(ROOT).as_posix(), f"{doc}, {section!r}"))
    assert missing == []


def test_no_module_cites_the_design_notes_outside_the_repository():
    citing = {p.relative_to(ROOT).as_posix() for p in CODE if "DESIGN.md" in p.read_text("utf-8")}
    assert citing <= DESIGN_CITED_UNTIL_SPLIT, sorted(citing - DESIGN_CITED_UNTIL_SPLIT)
