"""docs/formats.md and the code cannot drift: every example is read by the reader its block
names (``reader=``) and its header equals the column list it names (``columns=``); every
section has an example or says why not; every reader of core/io is exercised."""

from __future__ import annotations

import csv
import importlib
import io
import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "formats.md"
_FENCE = re.compile(r"^```(\w+)([^\n]*)\n(.*?)^```", re.M | re.S)


def _sections() -> list[tuple[str, str]]:
    text = DOC.read_text(encoding="utf-8")
    parts = re.split(r"^## (.+)$", text, flags=re.M)
    return list(zip(parts[1::2], parts[2::2]))


def _examples() -> list[tuple[str, str, dict[str, str], str]]:
    out = []
    for title, body in _sections():
        for lang, info, content in _FENCE.findall(body):
            tags = dict(re.findall(r"(\w+)=(\S+)", info))
            if tags:
                out.append((title, lang, tags, content))
    return out


def _resolve(dotted: str):
    module, name = dotted.rsplit(".", 1)
    return getattr(importlib.import_module(f"lidarphoto.{module}"), name)


EXAMPLES = _examples()


def _id(example) -> str:
    title, _, tags, _ = example
    return f"{title}: {tags.get('reader') or tags.get('columns')}"


def test_every_section_has_an_example_or_says_why_not():
    for title, body in _sections():
        if title.startswith("Common rules") or title == "Accuracy figures":
            continue
        tagged = any(re.search(r"\w+=\S+", info) for _, info, _ in _FENCE.findall(body))
        assert tagged or "<!-- no example:" in body, title


@pytest.mark.parametrize("example", EXAMPLES, ids=_id)
def test_example_is_read_by_its_reader_and_matches_its_columns(example, tmp_path):
    title, lang, tags, content = example
    assert lang in ("csv", "json", "xml", "text"), title
    path = tmp_path / f"example.{'txt' if lang == 'text' else lang}"
    path.write_text(content, encoding="utf-8")
    if "columns" in tags:
        expected = tuple(_resolve(tags["columns"]))
        if lang == "csv":
            header = next(csv.reader(io.StringIO(content)))
            assert tuple(header) == expected, title
        else:
            assert tuple(json.loads(content)) == expected, title
    if "reader" in tags:
        result = _resolve(tags["reader"])(path)
        assert result is not None
        try:
            assert len(result) > 0, title
        except TypeError:  # an object without a length (a camera): it was built
            pass


# readers that cannot run on the example alone: a photograph; a table whose rows must name
# photos that exist next to it (its columns are still documented in formats.md)
_NEEDS_MORE_THAN_THE_FILE = {"control_chips.read_grey_photo", "control_chips.read_photo_table"}


def test_every_table_reader_of_core_io_has_an_example():
    named = {tags["reader"] for _, _, tags, _ in EXAMPLES if "reader" in tags}
    # no text example possible: LAS/LAZ, GeoTIFF, BAL, E57, SBET (chips: GeoTIFF; tiles: LAS/LAZ;
    # calibration, images: photographs)
    # colmap: a folder of three files (text or binary), written and read in test_colmap.py
    binary = {"bal", "calibration", "chips", "colmap", "dsm", "images", "pointcloud", "raster",
              "sbet", "scans", "tiles"}  # fmt: skip
    for module in sorted((ROOT / "core" / "io").glob("*.py")):
        if module.stem in binary:
            continue
        for name in re.findall(r"^def (read_\w+)\(", module.read_text(encoding="utf-8"), re.M):
            if name == "read_table":  # the generic CSV reader under all of them
                continue
            if f"{module.stem}.{name}" in _NEEDS_MORE_THAN_THE_FILE:
                continue
            assert f"core.io.{module.stem}.{name}" in named, f"{module.stem}.{name}"


def test_the_accuracy_json_has_the_documented_keys():
    from lidarphoto.core.quality.accuracy_json import JSON_TOP_KEYS, report_to_dict
    from test_accuracy_names import small_report

    assert tuple(report_to_dict(small_report())) == JSON_TOP_KEYS


def test_conventions_points_to_formats():
    text = (ROOT / "docs" / "conventions.md").read_text(encoding="utf-8")
    assert "formats.md" in text
