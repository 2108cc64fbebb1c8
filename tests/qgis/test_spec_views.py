"""Every algorithm's three views agree: the core spec, the QGIS algorithm and the command line.

Names and kinds are compared one by one; defaults by reading, through each view, the values a
run gets when the user gives only the required parameters.
"""

from __future__ import annotations

import argparse

import pytest
from lidarphoto.core.cli import build_parser
from lidarphoto.core.jobs import ALGORITHMS
from lidarphoto.core.jobs.spec import parse_values
from lidarphoto.processing_provider.parameters import read_parameter
from qgis.core import QgsProcessingContext, QgsProject

#: QGIS parameter type() of each spec kind
QGIS_TYPE = {
    "file": "file",
    "raster": "raster",
    "pointcloud": "pointcloud",
    "surface": "layer",
    "table": "vector",
    "crs": "crs",
    "number": "number",
    "integer": "number",
    "boolean": "boolean",
    "enum": "enum",
    "string": "string",
    "numbers": "string",
    "points": "source",
    "field": "field",
    "file_out": "fileDestination",
    "raster_out": "rasterDestination",
    "folder_out": "folderDestination",
    "sink": "sink",
    "files": "multilayer",
}
SPECS = {job.SPEC.name: job.SPEC for job in ALGORITHMS}


def _subparser(name: str) -> argparse.ArgumentParser:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices[name]


def _required(spec) -> dict[str, str]:
    """A value for every required parameter (files need not exist: nothing is run)."""
    out = {}
    for p in spec.params:
        if p.required and p.kind != "sink":
            out[p.name] = "EPSG:31983" if p.kind == "crs" else f"/tmp/{p.name.lower()}.csv"
    for p in spec.params:  # a CRS with a QGIS-only default is given in both views
        if p.kind == "crs" and p.qgis_default is not None:
            out[p.name] = "EPSG:31983"
    return out


def test_every_algorithm_is_in_every_view(provider):
    """Each spec in QGIS and on the command line; in QGIS also the ground filter's
    one-method forms (the same job, METHOD fixed)."""
    variants = {f"groundfilter{m}" for m in ("smrf", "pmf", "csf")}
    assert [a.name() for a in provider.algorithms()] == sorted({*SPECS, *variants})
    assert set(_subparser_names()) == set(SPECS)


def _subparser_names() -> list[str]:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return list(sub.choices)


@pytest.mark.parametrize("name", sorted(SPECS))
def test_names_and_kinds_agree(provider, name):
    spec = SPECS[name]
    alg = provider.algorithm(name)
    qgis = [(d.name(), d.type()) for d in alg.parameterDefinitions()]
    from lidarphoto.processing_provider.parameters import is_extent, layer_input

    def kind(p):
        if p.kind == "pointcloud" and not layer_input(p):
            return "file"  # QGIS without a point-cloud provider (PDAL)
        if p.kind == "numbers":
            return "extent" if is_extent(p) else "matrix"
        return QGIS_TYPE[p.kind]

    kinds = [kind(p) for p in spec.params]
    assert qgis == list(zip([p.name for p in spec.params], kinds))
    for p in spec.params:
        d = alg.parameterDefinition(p.name)
        if p.kind in ("number", "integer"):
            assert (d.dataType() == d.Type.Integer) == (p.kind == "integer"), p.name
        if p.kind == "enum":
            assert d.allowMultiple() == p.multiple and len(d.options()) == len(p.options)
        optional = bool(d.flags() & d.Flag.FlagOptional)
        matrix = p.kind == "numbers" and p.default is not None  # see make_parameter
        assert optional == (p.optional or (p.kind == "field") or matrix), p.name
    assert {o.name() for o in alg.outputDefinitions()} >= {r.name for r in spec.results}
    cli = [a.dest for a in _subparser(name)._actions if a.option_strings and a.dest != "help"]
    assert cli == [p.name for p in spec.params if p.kind != "sink"]


@pytest.mark.parametrize("name", sorted(SPECS))
def test_defaults_agree(provider, name):
    spec = SPECS[name]
    alg = provider.algorithm(name)
    given = _required(spec)
    # command line: what argparse hands to the job
    argv = [name]
    for key, value in given.items():
        argv += ["--" + key.lower().replace("_", "-"), value]
    args = _subparser(name).parse_args(argv[1:])
    cli = parse_values(spec, {k: v for k, v in vars(args).items() if v is not None and k != "job"})
    # QGIS: what the algorithm reads from its parameters
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    parameters = {**given}
    for p in spec.params:
        if p.kind == "points":
            parameters.pop(p.name, None)
    raw = {
        p.name: read_parameter(alg, p, parameters, context)
        for p in spec.params
        if p.kind not in ("sink", "file_out", "raster_out", "folder_out")
    }
    qgis = parse_values(spec, raw)
    for p in spec.inputs:
        assert qgis[p.name] == cli[p.name] == parse_values(spec, given)[p.name], p.name
        if p.default is not None and p.kind != "crs":
            expected = p.default if p.kind != "enum" or not p.multiple else tuple(p.default)
            if p.kind == "numbers":
                expected = tuple(float(v) for v in p.default)
            assert cli[p.name] == expected, p.name


@pytest.mark.parametrize("name", sorted(SPECS))
def test_help_shows_defaults_and_units(provider, name):
    spec = SPECS[name]
    html = provider.algorithm(name).shortHelpString()
    text = _subparser(name).format_help()
    for p in spec.params:
        assert f"<b>{p.name}</b>" in html
        default = p.default_text()
        if default and p.kind != "sink":
            assert default in html, p.name
        if p.unit:
            assert p.unit in html, p.name
    for p in spec.params:
        if p.kind != "sink" and p.default_text():
            assert f"default: {p.default_text()}" in " ".join(text.split()), p.name
