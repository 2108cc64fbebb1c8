"""Defaults live once, in the science: every spec parameter mapped to a dataclass field shows
that field's default, the options a job builds from the defaults are the dataclass's own, and
no spec retypes a default its dataclasses hold."""

from __future__ import annotations

import dataclasses
import importlib
import os

import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.jobs import ALGORITHMS
from lidarphoto.core.jobs.spec import Ref, options_from, parse_values

SPECS = {job.SPEC.name: job.SPEC for job in ALGORITHMS}

#: Parameters named like a field of their job's dataclasses that are not that field, and why.
NOT_THE_FIELD: set[tuple[str, str]] = set()


def _class(ref: Ref) -> type:
    return getattr(importlib.import_module(f"lidarphoto.core.{ref.module}"), ref.name)


def _mapped() -> list[tuple[str, str]]:
    return [(s.name, p.name) for s in SPECS.values() for p in s.params if p.source is not None]


@pytest.mark.parametrize(("name", "key"), _mapped())
def test_a_mapped_default_is_the_fields(name, key):
    """The default an instance made with no arguments holds (default_factory and
    ``__post_init__`` included), value and type."""
    p = SPECS[name].param(key)
    cls = _class(p.source)
    science = getattr(cls(), p.source.field)
    if p.source.convert is not None:  # a unit of the spec's (arcseconds for radians)
        science = p.source.convert(science)
    assert p.default == (tuple(science) if isinstance(science, list) else science), key
    if isinstance(science, (int, float)) and not isinstance(science, bool):
        assert p.minimum is None or p.minimum <= science, f"{key}: default below its range"
        assert p.maximum is None or science <= p.maximum, f"{key}: default above its range"


def test_most_defaults_come_from_the_science():
    assert len(_mapped()) >= 80  # 56 retyped literals before, now none


@pytest.mark.parametrize("name", sorted(SPECS))
def test_options_built_from_the_defaults_are_the_sciences(name):
    """The job's parameter table turned into each dataclass it maps (options_from, as run()
    does) gives the dataclass's defaults: a wrong field name or a value converted twice fails."""
    spec = SPECS[name]
    required = {p.name: "x" for p in spec.inputs if p.required}
    values = parse_values(spec, required)
    for ref in {p.source for p in spec.params if p.source is not None}:
        cls = _class(ref)
        if cls.__name__ == "LocateOptions":  # holds an LsmOptions: built with it by the job
            continue
        assert options_from(cls, spec, values) == cls(), (name, cls.__name__)


def _normal(name: str) -> str:
    for suffix in ("_m", "_px", "_deg", "_rad"):
        name = name.removesuffix(suffix)
    return name.replace("_", "")


@pytest.mark.parametrize("name", sorted(SPECS))
def test_no_spec_retypes_a_default_of_its_dataclasses(name):
    """A parameter with a literal default named like a field of a dataclass the spec reads
    (units suffixes aside) must read it instead (or be listed in NOT_THE_FIELD)."""
    spec = SPECS[name]
    classes = {_class(p.source) for p in spec.params if p.source is not None}
    fields = {_normal(f.name): (c.__name__, f.name) for c in classes
              for f in dataclasses.fields(c)}  # fmt: skip
    retyped = [
        (p.name, *fields[_normal(p.name.lower())])
        for p in spec.inputs
        if p.source is None and p.default is not None and (name, p.name) not in NOT_THE_FIELD
        and _normal(p.name.lower()) in fields
        and not (isinstance(p.default, str) and p.default == "")
    ]
    assert retyped == [], retyped


def _changed(value):
    """A value other than ``value`` of the same kind (None: no simple other value)."""
    if isinstance(value, bool):
        return not value
    if isinstance(value, int):
        return value + 1
    if isinstance(value, float):
        return value * 0.9 if value else 0.1
    return None


@pytest.mark.parametrize(("name", "key"), _mapped())
def test_a_value_given_reaches_the_options(name, key):
    """A value other than the default reaches the dataclass options_from builds: a field is
    never left at its default because the class moved to another module (it happened: the
    bundle's and the boresight's options moved when their files were split, and GROUPING and
    the bundle's switches were dropped without a word)."""
    spec = SPECS[name]
    p = spec.param(key)
    if p.source.convert is not None:
        pytest.skip("converted: given by the job as an extra")
    if getattr(p, "multiple", False):
        pytest.skip("a list of choices")
    new = _changed(p.default) if not p.options else next(
        (o for o in p.options if o != p.default), None)  # fmt: skip
    if new is None:
        pytest.skip("no simple other value")
    values = {q.name: q.default for q in spec.params}
    values[key] = new
    try:
        opts = options_from(_class(p.source), spec, values)
    except InputError as exc:  # the other value breaks a rule between fields (not dropped)
        pytest.skip(f"the science refuses it with the other defaults: {exc}")
    assert getattr(opts, p.source.field) == new


_TWIN = """
import dataclasses, sys
from main.core.jobs.spec import AlgorithmSpec, Param, Ref, options_from
from lidarphoto.core.lidar.roof_planes import RoofPlaneParams

spec = AlgorithmSpec("x", "X", "G", "g", "s", "d", (Param("EPSILON", "number", "E",
    Ref("lidar.roof_planes", "RoofPlaneParams", "epsilon")),))
assert options_from(RoofPlaneParams, spec, {"EPSILON": 0.2}).epsilon == 0.2

@dataclasses.dataclass
class RoofPlaneParams:  # a class of that name elsewhere: refused
    epsilon: float = 0.1
try:
    options_from(RoofPlaneParams, spec, {"EPSILON": 0.2})
except TypeError as exc:
    print(exc)
"""


def test_a_field_is_found_when_the_core_is_imported_under_two_names(tmp_path):
    """The plugin folder imported as ``main`` too (pytest's --doctest-modules names it after
    the checkout's folder): its specs take the dataclasses of ``lidarphoto.core``, the same
    classes under the other name; a class of that name from another module is refused."""
    import subprocess
    import sys
    from pathlib import Path

    import lidarphoto

    (tmp_path / "main").symlink_to(Path(lidarphoto.__file__).parent, target_is_directory=True)
    env = {**os.environ, "PYTHONPATH": str(tmp_path)}
    run = subprocess.run([sys.executable, "-c", _TWIN], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=120)  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == ("x: parameters EPSILON (lidar.roof_planes.RoofPlaneParams."
                                  "epsilon) do not name __main__.RoofPlaneParams")  # fmt: skip
