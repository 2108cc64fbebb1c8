"""The command line mirrors the toolbox: same algorithm ids, same parameter names."""

from __future__ import annotations

import configparser
from pathlib import Path

import tomllib
from lidarphoto.core.cli import parameter_names
from qgis_helpers import ROOT


def test_cli_options_are_the_processing_parameters(provider):
    for algorithm in provider.algorithms():
        # outputs only QGIS can make (feature sinks: layers) have no command-line counterpart
        qgis_names = {p.name() for p in algorithm.parameterDefinitions() if p.type() != "sink"}
        assert set(parameter_names(algorithm.name())) == qgis_names, algorithm.name()


def test_versions_agree():
    meta = configparser.ConfigParser()
    meta.read(Path(ROOT) / "metadata.txt", encoding="utf-8")
    with open(Path(ROOT) / "pyproject.toml", "rb") as fh:
        project = tomllib.load(fh)["project"]
    assert project["version"] == meta.get("general", "version")
