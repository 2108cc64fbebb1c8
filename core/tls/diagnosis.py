"""Why a TLS calibration cannot separate two parameters, and what network design breaks their
correlation (Lichti 2010): the hints the report and the not-observable errors give."""

from __future__ import annotations

from collections.abc import Sequence

from .aps import AP_TERMS

_DESIGN_HINTS = {
    ("a0", "position"): "the rangefinder offset moves every target along its line of sight, "
    "which a shift of the station mimics when its targets lie mostly on one side or mostly "
    "above or below the horizon: targets all around the scanner and over the full vertical "
    "range, or stations tilted by about 90 degrees, separate them",
    ("a1", "position"): "the range scale changes the size of the network, as the station "
    "positions do unless a known distance fixes it: give control coordinates",
    ("b1", "kappa"): "the collimation error sec(alpha) is about constant for targets near "
    "the horizon, like a rotation of the station about its vertical axis: targets at high "
    "elevation (ceiling, floor), two-face observations or tilted stations separate them",
    ("b2", "tilt"): "the trunnion axis error tan(alpha) and a tilt of the station both turn "
    "the directions to high targets: targets all around the scanner at several elevations, "
    "two-face observations or stations tilted by 90 degrees separate them",
    ("c0", "tilt"): "the vertical index error is a constant offset of the vertical angles, "
    "like a tilt of the station when its targets lie in a narrow horizontal sector: targets "
    "all around the scanner or two-face observations separate them",
    ("c0", "position"): "the vertical index error raises far targets more than near ones, "
    "like a change of the station height over a narrow range of distances: targets at "
    "several distances and elevations, or tilted stations, separate them",
    ("ap", "ap"): "these two terms have nearly the same shape over the observed angles "
    "and ranges: keep the physically expected one (automatic selection drops the less "
    "significant) or observe a wider range of angles and distances",
}


def _param_kind(name: str) -> str:
    if name in AP_TERMS:
        return "ap"
    tail = name.rsplit(".", 1)[-1]
    if tail in ("X", "Y", "Z"):
        return "position"
    if tail == "kappa":
        return "kappa"
    if tail in ("omega", "phi"):
        return "tilt"
    return "other"


def explain_pair(a: str, b: str) -> str:
    """Why two parameters (AP or station parameter names) are correlated, and the network
    design that separates them (Lichti 2010); "" when no explanation is known.

    >>> explain_pair("b1", "S1.kappa").startswith("the collimation error")
    True
    """
    ka, kb = _param_kind(a), _param_kind(b)
    if ka == "ap" and kb == "ap":
        return _DESIGN_HINTS[("ap", "ap")]
    if kb == "ap":
        a, b, ka, kb = b, a, kb, ka
    if ka != "ap":
        return ""
    for key in ((a, kb), (a, "position" if kb == "position" else kb)):
        if key in _DESIGN_HINTS:
            return _DESIGN_HINTS[key]
    if a in ("a2", "a3") and kb == "position":
        return _DESIGN_HINTS[("a0", "position")]
    return ""


def diagnose(parameters: Sequence[str], has_control: bool) -> list[str]:
    """Sentences that explain a non-observable set of parameters (names of the adjustment).

    >>> diagnose(["a1", "S1.X"], has_control=False)[0][:40]
    'a1 (range scale error) cannot be separat'
    """
    out = []
    names = set(parameters)
    aps = [p for p in parameters if p in AP_TERMS]
    if "a1" in names and not has_control:
        out.append(
            "a1 (range scale error) cannot be separated from the scale of a network without "
            "control: give control targets with known coordinates (at least two, far apart) "
            "or leave a1 out."
        )
    for ap in aps:
        if ap == "a1" and not has_control:
            continue
        out.append(
            f"{ap} ({AP_TERMS[ap].cause}) is not determined by this network: "
            + (
                explain_pair(ap, next((p for p in parameters if p not in AP_TERMS), ap))
                or "observe a wider range of angles, ranges and station set-ups"
            )
            + "."
        )
    stations = sorted({p.split(".")[0] for p in parameters if p not in AP_TERMS})
    if stations and not aps:
        out.append(
            "The datum or a station is undetermined ("
            + ", ".join(stations[:6])
            + (" ..." if len(stations) > 6 else "")
            + "): each station needs three targets in common with the network that are not "
            "collinear, and the network needs control (three targets) or a reference station."
        )
    if not out:
        out.append("Parameters not determined: " + ", ".join(parameters[:20]) + ".")
    return out
