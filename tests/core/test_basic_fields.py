"""Forms a first run can fill: every algorithm's form shows at most MAX_BASIC fields outside
Advanced (the required inputs, the main outputs and the few options a first run sets), and no
parameter a run cannot do without hides under Advanced.

The ground filter's toolbox forms are its one-method algorithms (groundfiltersmrf, ...: the
common fields and that method's, METHOD fixed; ``processing_provider/algorithms/
ground_filter.py``); the all-methods ``groundfilter`` is hidden from the toolbox."""

from __future__ import annotations

import pytest
from lidarphoto.core.jobs import ALGORITHMS, ground_filter
from lidarphoto.core.jobs.spec import Param

#: The most fields outside Advanced (inputs and outputs) of one form.
MAX_BASIC = 12
SPECS = {job.SPEC.name: job.SPEC for job in ALGORITHMS}


def _forms() -> dict[str, tuple[Param, ...]]:
    """{form name: its parameters} as the QGIS toolbox shows them."""
    forms = {name: spec.params for name, spec in SPECS.items() if name != "groundfilter"}
    spec = SPECS["groundfilter"]
    for method in ("smrf", "pmf", "csf"):
        forms[f"groundfilter{method}"] = tuple(
            p for p in spec.params
            if p.name != "METHOD" and ground_filter.PARAM_METHODS.get(p.name, "") in ("", method)
        )  # fmt: skip
    return forms


FORMS = _forms()


@pytest.mark.parametrize("name", sorted(FORMS))
def test_a_form_shows_at_most_twelve_basic_fields(name):
    basic = [p.name for p in FORMS[name] if not p.advanced]
    assert len(basic) <= MAX_BASIC, f"{name}: {len(basic)} basic fields {basic}"


@pytest.mark.parametrize("name", sorted(SPECS))
def test_a_required_parameter_is_basic(name):
    """An input with no default that is not optional, and an output that is not optional,
    stay outside Advanced (the user must see what must be given or where it goes)."""
    hidden = [p.name for p in SPECS[name].params if p.advanced and (p.required or (
        p.is_output and not p.optional))]  # fmt: skip
    assert hidden == [], f"{name}: required but under Advanced: {hidden}"


def test_the_one_method_forms_are_the_ground_filters_fields():
    """Every ground-filter parameter is in one of the one-method forms (none is lost by
    leaving the all-methods form out of the count), METHOD excepted."""
    shown = {p.name for m in ("smrf", "pmf", "csf") for p in FORMS[f"groundfilter{m}"]}
    assert shown == set(SPECS["groundfilter"].names) - {"METHOD"}


def test_a_layer_twin_names_a_layer_output_of_its_algorithm():
    twins = 0
    for spec in SPECS.values():
        sinks = {p.name for p in spec.outputs if p.kind == "sink"}
        for p in spec.params:
            if p.layer_twin:
                twins += 1
                assert p.kind == "file_out" and p.layer_twin in sinks, (spec.name, p.name)
    assert twins == 5  # bundle points, boresight residuals, monoplot, LCPs, trajectory EO
