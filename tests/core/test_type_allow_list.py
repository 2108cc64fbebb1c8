"""The mypy allow-list of pyproject.toml (scripts/test.sh runs mypy on core next to ruff): every
module it names exists, once, and the list stays sorted, so that a module renamed or split
does not keep an entry that no longer shields anything, nor hides a new module's errors."""

from __future__ import annotations

from pathlib import Path

import pytest

tomllib = pytest.importorskip("tomllib")  # Python 3.11+
ROOT = Path(__file__).resolve().parents[2]


def test_every_allowed_module_exists_once_and_in_order():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["mypy"]
    assert config["files"] == ["core"]
    (allowed,) = [o["module"] for o in config["overrides"] if o.get("ignore_errors")]
    assert allowed == sorted(set(allowed))
    for name in allowed:
        path = ROOT.joinpath(*name.split("."))
        assert path.with_suffix(".py").is_file() or (path / "__init__.py").is_file(), name
    assert len(allowed) <= 43  # the list only shrinks
