"""Every algorithm's help (QGIS HTML and ``lidarphoto <alg> --help``), generated from its spec,
gives each parameter's default, unit and valid range, a "How to use" with a typical chain,
and references that are in docs/references.md."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest
from lidarphoto.core.cli import build_parser
from lidarphoto.core.jobs import ALGORITHMS
from lidarphoto.core.jobs.spec import facts_line, param_facts
from lidarphoto.core.jobs.workflows import WORKFLOWS, workflows_of

ROOT = Path(__file__).resolve().parents[2]
SPECS = {job.SPEC.name: job.SPEC for job in ALGORITHMS}


def _cli_help(name: str) -> str:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return " ".join(sub.choices[name].format_help().split())


@pytest.mark.parametrize("name", sorted(SPECS))
def test_help_lists_default_unit_and_range_of_every_parameter(name):
    spec = SPECS[name]
    html = spec.help_html()
    cli = _cli_help(name)
    for p in spec.params:
        default, unit, rng = param_facts(p, spec)
        row = re.search(rf"<tr><td><b>{p.name}</b></td>(.*?)</tr>", html)
        assert row, p.name
        cells = re.findall(r"<td>(.*?)</td>", row.group(1))
        assert cells[1:] == [c.replace("&", "&amp;").replace(">", "&gt;")
                             for c in (default, unit, rng)], p.name  # fmt: skip
        if p.kind in ("number", "integer", "numbers"):
            assert unit and rng, f"{name}.{p.name}: a number needs a unit and a range"
        if p.kind != "sink":
            assert " ".join(facts_line(p, spec).split()) in cli, p.name


def test_a_length_parameter_says_what_unit_it_is_in():
    spec = SPECS["createlcps"]
    _, unit, rng = param_facts(spec.param("DELTA"), spec)
    assert unit == "length (cloud CRS unit, or m when DISTANCE_UNIT is metre)"
    assert rng == "0.001 to 1000"
    assert param_facts(spec.param("MAX_CONDITION"), spec)[1] == "none"


@pytest.mark.parametrize("name", sorted(SPECS))
def test_help_has_how_to_use_with_a_chain(name):
    spec = SPECS[name]
    assert workflows_of(name), f"{name} is in no workflow (core/jobs/workflows.py)"
    chain = workflows_of(name)[0].chain(name)
    assert f"[{name}]" in chain and " -> " in chain
    html = spec.help_html()
    assert "<h3>How to use</h3>" in html and chain.replace(">", "&gt;") in html
    assert "How to use:" in spec.help_text() and "(this algorithm)" in spec.help_text()
    assert " ".join(chain.split()) in _cli_help(name)


def test_workflow_steps_are_algorithms_and_name_their_own_parameters():
    for w in WORKFLOWS:
        for alg, note in w.steps:
            assert alg in SPECS, (w.title, alg)
            names = set(SPECS[alg].names)
            # NAMES_WITH_UNDERSCORES and "NAME =" are parameter names of that step
            given = set(re.findall(r"\b[A-Z][A-Z0-9]*(?:_[A-Z0-9]+)+\b", note))
            given |= set(re.findall(r"\b([A-Z][A-Z0-9_]*) (?:and [A-Z_]+ )?=", note))
            assert given <= names, (alg, sorted(given - names))


def test_the_boresight_chain_is_the_one_of_the_paper():
    chain = workflows_of("boresightcalibration")[0].chain()
    assert "groundfilter -> extractroofplanes -> createlcps -> boresightcalibration" in chain


@pytest.mark.parametrize("name", sorted(SPECS))
def test_references_name_authors_and_year_and_are_in_references_md(name):
    spec = SPECS[name]
    refs = (ROOT / "docs" / "references.md").read_text(encoding="utf-8")
    assert spec.references, f"{name} cites no method"
    for r in spec.references:
        assert f"**{r}" in refs, r
        assert re.search(r"\(\d{4}\)|\(n\. ?d\.\)", r) or "year not stated" in refs.split(
            f"**{r}"
        )[1][:80], r
    assert "References: " in spec.help_text() and "<h3>References</h3>" in spec.help_html()


def test_workflow_texts_share_the_help_catalogue_context():
    from lidarphoto.core.jobs import spec, workflows

    assert workflows.TR_CONTEXT == spec.TR_CONTEXT
