"""Declarative parameter specs: each algorithm's parameters written once, for every view.

A job module (``core/jobs/<algorithm>.py``) declares ``SPEC``, an :class:`AlgorithmSpec` whose
:class:`Param` entries carry the name (the QGIS key, ``CELL_SIZE``, and the command-line
option, ``--cell-size``), the kind, label, default, unit, valid range and help. The QGIS
algorithm (``processing_provider/base.py``), the command line (``core/cli.py``) and both help texts
are generated from it, so a default or a help text is written in one place.

Defaults, choices and ranges that belong to the science are not retyped: a :class:`Ref`
names them (``Ref("photo.tie_points", "TiePointOptions", "ratio")``, or through
:class:`Fields`), and they are read from the science the first time the spec's parameters are
used (:attr:`AlgorithmSpec.params`). Listing the algorithms (``lidarphoto --help``, the
registry of :mod:`core.jobs`) reads only names and summaries and imports no science.

Kinds of inputs (the value a job receives):

========== =================================== ==========================================
kind       QGIS parameter                      value
========== =================================== ==========================================
file       QgsProcessingParameterFile          path (str) or None
raster     QgsProcessingParameterRasterLayer   path (str) or None: a raster layer's file,
                                               or a file
pointcloud …ParameterPointCloudLayer where     path (str) or None: a point-cloud layer's
           QGIS reads LAS/LAZ (PDAL), else     file, or a file
           QgsProcessingParameterFile
surface    QgsProcessingParameterMapLayer      path (str) or None: a DSM, raster or LAS/LAZ
           (rasters; clouds with PDAL)         (a layer's file, or a file)
table      QgsProcessingParameterVectorLayer   path (str) or None: the CSV file of a layer
           (any geometry or none)              (delimited text or OGR), or a CSV file
crs        QgsProcessingParameterCrs           authority id or WKT (str) or None
number     QgsProcessingParameterNumber        float
integer    QgsProcessingParameterNumber (int)  int
boolean    QgsProcessingParameterBoolean       bool
enum       QgsProcessingParameterEnum          option name (tuple of names if multiple)
string     QgsProcessingParameterString        str
numbers    QgsProcessingParameterString        tuple of ``count`` floats ("x,y,z")
points     QgsProcessingParameterFeatureSource path of a point table (CLI); the QGIS
                                               adapter hands the job its own object
field      QgsProcessingParameterField         column / field name (str), "" when none
files      QgsProcessingParameterMultipleLayers tuple of paths (files or folders) or None
           (files)
========== =================================== ==========================================

The layer kinds (``raster``, ``pointcloud``, ``surface``, ``table``) reach the job as the path
of the file behind the layer, exactly as ``file`` does; on the command line they are paths.
The QGIS adapter refuses, naming the parameter, a layer that is not backed by such a file (a
memory layer, a database table, a web service).

Outputs: ``file_out`` (QgsProcessingParameterFileDestination), ``raster_out``
(…RasterDestination), both a path or None; ``folder_out`` (…FolderDestination): a folder
the job fills itself (not part of the runner's output set); ``sink`` (…FeatureSink): a layer,
QGIS only.
Results (numbers and strings a job reports) are :class:`Result` entries.
"""

from __future__ import annotations

import dataclasses
import importlib
import math
import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..errors import InputError

#: Input kinds whose value is the path of one file (a layer's file in QGIS).
FILE_KINDS = ("file", "raster", "pointcloud", "surface", "table")
INPUT_KINDS = (
    *FILE_KINDS,
    "crs",
    "number",
    "integer",
    "boolean",
    "enum",
    "string",
    "numbers",
    "points",
    "field",
    "files",
)
OUTPUT_KINDS = ("file_out", "raster_out", "folder_out", "sink")
RESULT_KINDS = ("number", "string")
_TRUE = ("true", "yes", "1", "on")
_FALSE = ("false", "no", "0", "off")
#: Translation context of the help's fixed words (``make i18n`` collects ``t("...")`` calls).
TR_CONTEXT = "AlgorithmHelp"


@dataclass(frozen=True)
class Ref:
    """A value of the science, read when first needed: ``Ref("photo.resection", "MODELS")`` is
    the constant ``MODELS`` of ``core/photo/resection.py``; with ``field``,
    ``Ref("photo.bundle", "BundleOptions", "robust")`` is the default of that dataclass field;
    ``convert`` turns the value into the spec's form (e.g. a label per choice).

    >>> Ref("lidar.roof_planes", "RoofPlaneParams", "k_neighbours").value()
    20
    """

    module: str  #: module below ``core`` ("photo.bundle")
    name: str  #: a constant or a dataclass of that module
    field: str = ""  #: a field of the dataclass ``name`` ("" for a constant)
    convert: Callable[[Any], Any] | None = None

    def value(self) -> Any:
        value = self.science_value()
        return value if self.convert is None else self.convert(value)

    def science_value(self) -> Any:
        """The value as the science holds it (before ``convert``)."""
        # relative to the core package, which the plugin may install under another name
        module = importlib.import_module(f"..{self.module}", __package__)
        obj = getattr(module, self.name)
        if not self.field:
            return obj
        for f in dataclasses.fields(obj):
            if f.name == self.field:
                if f.default is not dataclasses.MISSING:
                    return f.default
                if f.default_factory is not dataclasses.MISSING:
                    return f.default_factory()
                raise ValueError(f"{self}: the field has no default")
        raise AttributeError(f"{self.name} has no field {self.field!r}")

    def names(self, cls: type) -> bool:
        """Whether this is a field of the class ``cls``: the name of this module resolves to
        ``cls`` itself (a class moved to another module and imported back still is), or to
        its twin when the core is imported under two package names (a checkout's folder
        name and the plugin's): the same class and module path below ``core``."""
        if not self.field or cls.__name__ != self.name:
            return False
        module = importlib.import_module(f"..{self.module}", __package__)
        found = getattr(module, self.name, None)
        if found is cls:
            return True
        return (
            isinstance(found, type)
            and found.__qualname__ == cls.__qualname__
            and _below_core(found.__module__) == _below_core(cls.__module__)
        )

    def __str__(self) -> str:
        return f"{self.module}.{self.name}" + (f".{self.field}" if self.field else "")


def _below_core(module: str) -> str:
    """``lidarphoto.core.lidar.roof_planes`` -> ``lidar.roof_planes`` (any package name)."""
    return module.partition(".core.")[2] or module


class Fields:
    """The fields of a science dataclass as :class:`Ref` s, without importing it:
    ``BUNDLE = Fields("photo.bundle", "BundleOptions")``; ``BUNDLE.robust`` is
    ``Ref("photo.bundle", "BundleOptions", "robust")``."""

    def __init__(self, module: str, name: str) -> None:
        self.module, self.name = module, name

    def __getattr__(self, field_name: str) -> Ref:
        if field_name.startswith("_"):
            raise AttributeError(field_name)
        return Ref(self.module, self.name, field_name)

    def params(
        self, rows: Iterable[Sequence[Any]], help: Mapping[str, str] | None = None
    ) -> tuple[Param, ...]:
        """One :class:`Param` a row ``(parameter, field, label, kind, unit, minimum, maximum,
        advanced)``, its default read from that field of the dataclass; ``help`` by
        parameter name."""
        notes = help or {}
        return tuple(
            Param(
                key,
                kind,
                label,
                getattr(self, field_name),
                unit=unit,
                minimum=minimum,
                maximum=maximum,
                advanced=advanced,
                help=notes.get(key, ""),
            )
            for key, field_name, label, kind, unit, minimum, maximum, advanced in rows
        )


#: The fields of :class:`Param` a :class:`Ref` may stand for.
_REF_FIELDS = ("default", "minimum", "maximum", "options", "labels")


@dataclass(frozen=True)
class Param:
    """One parameter of an algorithm (see the module docstring for the kinds).

    ``unit`` is shown with the label and in the help ("m", "deg", "px", "cloud unit", ...);
    ``minimum``/``maximum`` bound numbers, and each of ``numbers``, to the physically
    meaningful range (both views refuse values outside, naming the parameter); ``options``
    are an enum's machine names (what the command line takes; QGIS shows ``labels``);
    ``aliases`` are extra command-line spellings of options; ``qgis_default`` overrides
    ``default`` in QGIS only (e.g. ``"ProjectCrs"``); ``suffixes`` are the file endings the job
    reads from a folder given to a ``files`` (or ``file``) input (empty: every file), which no
    output may overwrite. ``default``, ``minimum``, ``maximum``, ``options`` and ``labels`` may
    be a :class:`Ref`, resolved by :meth:`resolved`; a default read from a dataclass field
    keeps that field in ``source`` (see :func:`options_from`). ``layer_twin`` names, on a table
    output, the layer output (``sink``) that carries the same rows: QGIS loads the table as a
    layer only when that layer was not written.
    """

    name: str
    kind: str
    label: str
    default: Any = None
    help: str = ""
    unit: str = ""
    optional: bool = False
    advanced: bool = False
    minimum: float | None = None
    maximum: float | None = None
    options: tuple[str, ...] = ()
    labels: tuple[str, ...] = ()
    aliases: Mapping[str, str] = field(default_factory=dict)
    multiple: bool = False
    count: int = 0
    file_filter: str = ""
    create_by_default: bool = True
    geometry: str = ""
    parent: str = ""
    numeric_field: bool = False
    qgis_default: Any = None
    suffixes: tuple[str, ...] = ()
    source: Ref | None = None
    layer_twin: str = ""

    def __post_init__(self) -> None:
        if self.kind not in INPUT_KINDS + OUTPUT_KINDS:
            raise ValueError(f"{self.name}: unknown kind {self.kind!r}")
        if not re.fullmatch(r"[A-Z][A-Z0-9_]*", self.name):
            raise ValueError(f"{self.name}: names are upper case with underscores")
        if self.refs:
            return  # checked once resolved
        if self.kind == "enum" and not self.options:
            raise ValueError(f"{self.name}: an enum needs options")
        if self.labels and len(self.labels) != len(self.options):
            raise ValueError(f"{self.name}: one label per option")
        if self.kind == "numbers" and self.count < 1:
            raise ValueError(f"{self.name}: numbers need a count")

    @property
    def refs(self) -> tuple[str, ...]:
        """The fields that are still a :class:`Ref`."""
        return tuple(f for f in _REF_FIELDS if isinstance(getattr(self, f), Ref))

    def resolved(self) -> Param:
        """This parameter with its :class:`Ref` s read from the science (a tuple default
        stays a tuple, an enum's options a tuple of names).

        >>> p = Param("K", "integer", "Neighbours", Ref("lidar.roof_planes", "RoofPlaneParams",
        ...           "k_neighbours"))
        >>> p.resolved().default, str(p.resolved().source)
        (20, 'lidar.roof_planes.RoofPlaneParams.k_neighbours')
        """
        if not self.refs:
            return self
        values: dict[str, Any] = {}
        for name in self.refs:
            value = getattr(self, name).value()
            values[name] = tuple(value) if isinstance(value, (list, tuple)) else value
        if isinstance(self.default, Ref) and self.default.field:
            values["source"] = self.default
        return dataclasses.replace(self, **values)

    @property
    def option(self) -> str:
        """The command-line option: ``CELL_SIZE`` -> ``--cell-size``."""
        return "--" + self.name.lower().replace("_", "-")

    @property
    def is_output(self) -> bool:
        return self.kind in OUTPUT_KINDS

    @property
    def title(self) -> str:
        """The label with its unit, as both views show it."""
        return f"{self.label} ({self.unit})" if self.unit else self.label

    @property
    def required(self) -> bool:
        """The user must give it (no default, not optional)."""
        return not self.optional and self.default is None and self.kind not in ("sink",)

    def default_text(self) -> str:
        """The default as a user types it ("" when there is none)."""
        d = self.default
        if d is None or d == "" or d == ():
            return ""
        if self.kind == "enum" and self.multiple:
            return ",".join(d)
        if self.kind == "numbers":
            return ",".join(f"{v:g}" for v in d)
        if self.kind == "boolean":
            return "true" if d else "false"
        if isinstance(d, float):
            return f"{d:g}"
        return str(d)


@dataclass(frozen=True)
class Result:
    """A number or text the algorithm reports (QGIS output ``name``; printed by the CLI)."""

    name: str
    kind: str
    label: str

    def __post_init__(self) -> None:
        if self.kind not in RESULT_KINDS:
            raise ValueError(f"{self.name}: unknown result kind {self.kind!r}")


@dataclass(frozen=True)
class AlgorithmSpec:
    """An algorithm: id, names, help and its parameters.

    ``description`` is plain text: paragraphs separated by blank lines, ``## heading`` lines
    and ``- item`` lists; it becomes the QGIS help (HTML) and the command line's description.
    ``references`` are citations of docs/references.md ("Zhang et al. (2003)").
    """

    name: str
    title: str
    group: str
    group_id: str
    summary: str
    description: str
    params: tuple[Param, ...]
    results: tuple[Result, ...] = ()
    tags: tuple[str, ...] = ()
    references: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        params = self.__dict__.get("params", self.__dict__.get("_unresolved"))
        names = [p.name for p in params] + [r.name for r in self.results]
        dupes = {n for n in names if names.count(n) > 1}
        if dupes:
            raise ValueError(f"{self.name}: duplicate names {sorted(dupes)}")
        known = {p.name for p in params}
        for p in params:
            if p.kind == "field" and p.parent not in known:
                raise ValueError(f"{self.name}.{p.name}: unknown parent {p.parent!r}")
        if any(p.refs for p in params):
            # lazy: the science is imported when the parameters are first used (__getattr__)
            object.__setattr__(self, "_unresolved", tuple(params))
            object.__delattr__(self, "params")

    def __getattr__(self, name: str) -> Any:
        # only called for a missing attribute: ``params`` before its first use
        unresolved = self.__dict__.get("_unresolved")
        if name != "params" or unresolved is None:
            raise AttributeError(name)
        params = tuple(p.resolved() for p in unresolved)
        object.__setattr__(self, "params", params)
        return params

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.params)

    def param(self, name: str) -> Param:
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(name)

    @property
    def inputs(self) -> tuple[Param, ...]:
        return tuple(p for p in self.params if not p.is_output)

    @property
    def outputs(self) -> tuple[Param, ...]:
        return tuple(p for p in self.params if p.is_output)

    def help_html(self, tr: Callable[[str], str] | None = None) -> str:
        """The QGIS help: the description, how to use it (its workflows), the parameters with
        default, unit and range, and the references (authors, year). ``tr`` translates the
        fixed words (context ``AlgorithmHelp``; the spec's own texts are translated by
        :func:`core.jobs.translate.translate_spec`)."""
        from .workflows import how_to_use

        t = tr or _same
        parts = [text_to_html(self.description)]
        usage = how_to_use(self.name, tr)
        if usage:
            parts.append(text_to_html(f"## {t('How to use')}\n" + usage))
        rows = []
        for p in self.params:
            cells = (p.help or p.label, *param_facts(p, self, t))
            rows.append(
                f"<tr><td><b>{p.name}</b></td>"
                + "".join(f"<td>{_esc(c)}</td>" for c in cells)
                + "</tr>"
            )
        parts.append(
            f"<h3>{t('Parameters')}</h3><table><tr><th>{t('name')}</th><th>{t('meaning')}</th>"
            f"<th>{t('default')}</th><th>{t('unit')}</th><th>{t('valid range')}</th></tr>"
            + "".join(rows)
            + "</table>"
        )
        if self.references:
            items = "".join(f"<li>{_esc(r)}</li>" for r in self.references)
            parts.append(f"<h3>{t('References')}</h3><ul>{items}</ul>")
        return "\n".join(parts)

    def help_text(self, tr: Callable[[str], str] | None = None) -> str:
        """The command line's description (plain text): the description, how to use it and
        the references; each option's help gives its default, unit and range. ``tr`` as in
        :meth:`help_html`."""
        from .workflows import how_to_use

        t = tr or _same
        text = self.description
        usage = how_to_use(self.name, tr)
        if usage:
            text += f"\n\n## {t('How to use')}\n" + usage
        text = re.sub(r"(?m)^## (.*)$", r"\1:", text)
        if self.references:
            text += "\n\n" + t("References") + ": " + "; ".join(self.references) + "."
        return text


def _same(text: str) -> str:
    return text


def _esc(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def unit_text(p: Param, spec: AlgorithmSpec | None = None, t: Callable[[str], str] = _same) -> str:
    """The unit as the help shows it: the spec's unit; "length" spelt out where the algorithm
    has a DISTANCE_UNIT; "none" for a number without unit (a count, a ratio); "" otherwise.

    >>> unit_text(Param("K", "integer", "Neighbours", 20))
    'none'
    """
    if p.unit == "length" and spec is not None and "DISTANCE_UNIT" in spec.names:
        return t("length (cloud CRS unit, or m when DISTANCE_UNIT is metre)")
    if p.unit:
        return p.unit
    return t("none") if p.kind in ("number", "integer", "numbers") else ""


def range_text(p: Param, t: Callable[[str], str] = _same) -> str:
    """The valid range: "0.001 to 100", ">= 0", "<= 90", an enum's options, "any finite" for
    an unbounded number, or "".

    >>> range_text(Param("A", "number", "Angle", 1.0, minimum=0.0, maximum=90.0))
    '0 to 90'
    """
    if p.kind == "enum":
        return " | ".join(p.options)
    if p.minimum is not None and p.maximum is not None:
        return t("{} to {}").format(f"{p.minimum:g}", f"{p.maximum:g}")
    if p.minimum is not None:
        return f">= {p.minimum:g}"
    if p.maximum is not None:
        return f"<= {p.maximum:g}"
    return t("any finite") if p.kind in ("number", "integer", "numbers") else ""


def default_for_help(p: Param, t: Callable[[str], str] = _same) -> str:
    """The default as the help shows it: the value, or "optional" / "required"."""
    if p.is_output:
        return t("optional") if p.optional else t("required")
    text = p.default_text()
    return text if text else (t("optional") if p.optional else t("required"))


def param_facts(
    p: Param, spec: AlgorithmSpec | None = None, t: Callable[[str], str] = _same
) -> tuple[str, str, str]:
    """(default, unit, valid range) of a parameter, as every help shows them."""
    return default_for_help(p, t), unit_text(p, spec, t), range_text(p, t)


def facts_line(p: Param, spec: AlgorithmSpec | None = None, t: Callable[[str], str] = _same) -> str:
    """The facts of a parameter, e.g. "default: 0.15; unit: m; range: 0.001 to 100" (the parts
    that apply).

    >>> facts_line(Param("E", "number", "Epsilon", 0.15, unit="m", minimum=0.001))
    'default: 0.15; unit: m; range: >= 0.001'
    """
    default, unit, rng = param_facts(p, spec, t)
    has_value = p.default_text() != "" and not p.is_output
    bits = [t("default: {}").format(default) if has_value else default]
    if unit:
        bits.append(t("unit: {}").format(unit))
    if rng:
        bits.append((t("values: {}") if p.kind == "enum" else t("range: {}")).format(rng))
    return "; ".join(bits)


def text_to_html(text: str) -> str:
    r"""Plain-text help (paragraphs, ``## heading``, ``- item``) as simple HTML.

    >>> text_to_html("## Units\nIn metres.\n\n- a\n- b")
    '<h3>Units</h3><p>In metres.</p>\n<ul><li>a</li><li>b</li></ul>'
    """
    blocks = []
    for block in re.split(r"\n\s*\n", text.strip()):
        out: list[str] = []
        items: list[str] = []
        para: list[str] = []
        for line in block.splitlines():
            s = line.strip()
            if items and line.startswith("  ") and not s.startswith("- "):
                items[-1] += " " + s
            elif s.startswith("## "):
                _flush_para(out, para)
                _flush_items(out, items)
                out.append(f"<h3>{_esc(s[3:])}</h3>")
            elif s.startswith("- "):
                _flush_para(out, para)
                items.append(s[2:])
            else:
                _flush_items(out, items)
                para.append(s)
        _flush_para(out, para)
        _flush_items(out, items)
        blocks.append("".join(out))
    return "\n".join(blocks)


def _flush_para(out: list[str], para: list[str]) -> None:
    if para:
        out.append("<p>" + _esc(" ".join(para)) + "</p>")
        para.clear()


def _flush_items(out: list[str], items: list[str]) -> None:
    if items:
        out.append("<ul>" + "".join(f"<li>{_esc(i)}</li>" for i in items) + "</ul>")
        items.clear()


# ----------------------------------------------------------------------------- values
class Values(dict):
    """Parameter values by name, also readable as attributes in lower case.

    >>> v = Values({"CELL_SIZE": 1.0})
    >>> v.cell_size, v["CELL_SIZE"]
    (1.0, 1.0)
    """

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name.upper()]
        except KeyError:
            raise AttributeError(name) from None


def parse_numbers(text: str | Sequence[float], count: int, name: str) -> tuple[float, ...]:
    """``"0.1, -2, 3e-1"`` -> (0.1, -2.0, 0.3); exactly ``count`` finite numbers.

    >>> parse_numbers("0.12,-0.05,-1.35", 3, "LEVER_ARM")
    (0.12, -0.05, -1.35)
    """
    if isinstance(text, str):
        parts = [p for p in re.split(r"[,;\s]+", text.strip()) if p]
        try:
            values = tuple(float(p) for p in parts)
        except ValueError:
            raise InputError(f"{name}: '{text}' is not a list of numbers") from None
    else:
        values = tuple(float(v) for v in text)
    if len(values) != count:
        raise InputError(f"{name}: expected {count} numbers, got {len(values)} ('{text}')")
    if not all(math.isfinite(v) for v in values):
        raise InputError(f"{name}: every number must be finite ('{text}')")
    return values


def _enum_one(p: Param, raw: Any) -> str:
    if isinstance(raw, int) and not isinstance(raw, bool):
        if 0 <= raw < len(p.options):
            return p.options[raw]
    text = str(raw).strip()
    if text.isdigit() and int(text) < len(p.options):
        return p.options[int(text)]
    low = text.lower().replace("-", "_").replace(" ", "_")
    for opt in p.options:
        if low == opt.lower():
            return opt
    for alias, opt in p.aliases.items():
        if low == alias.lower():
            return opt
    raise InputError(f"{p.name}: '{raw}' is not one of {', '.join(p.options)}")


def parse_value(p: Param, raw: Any) -> Any:
    """Turn what the user gave (text on the command line, or a Python value) into the value
    of the parameter's kind; None (not given) becomes the default. Raises InputError naming
    the parameter when the value is malformed or out of range."""
    if raw is None or (isinstance(raw, str) and raw == "" and p.kind not in ("string", "field")):
        value = p.default
    elif p.kind == "number":
        try:
            value = float(raw)
        except (TypeError, ValueError):
            raise InputError(f"{p.name}: '{raw}' is not a number") from None
    elif p.kind == "integer":
        try:
            f = float(raw)
        except (TypeError, ValueError):
            raise InputError(f"{p.name}: '{raw}' is not an integer") from None
        if not f.is_integer():
            raise InputError(f"{p.name}: '{raw}' is not an integer")
        value = int(f)
    elif p.kind == "boolean":
        if isinstance(raw, bool):
            value = raw
        else:
            t = str(raw).strip().lower()
            if t not in _TRUE + _FALSE:
                raise InputError(f"{p.name}: expected true or false, got '{raw}'")
            value = t in _TRUE
    elif p.kind == "enum":
        if p.multiple:
            items = raw.split(",") if isinstance(raw, str) else list(raw)
            value = tuple(_enum_one(p, i) for i in items if str(i).strip() != "")
        else:
            value = _enum_one(p, raw)
    elif p.kind == "numbers":
        value = parse_numbers(raw, p.count, p.name)
    elif p.kind == "files":
        items = [raw] if isinstance(raw, str) else list(raw)
        value = tuple(str(i) for i in items if str(i).strip()) or p.default
    else:
        value = str(raw) if not isinstance(raw, str) else raw
    check_value(p, value)
    return value


def check_value(p: Param, value: Any) -> None:
    """Raise InputError when ``value`` is outside the parameter's range."""
    if value is None:
        if p.required and not p.is_output:
            raise InputError(f"{p.name} ({p.label}) is required")
        return
    if p.kind in ("number", "integer"):
        items = [("", value)]
    elif p.kind == "numbers":
        items = [(f" (number {k + 1} of {len(value)})", v) for k, v in enumerate(value)]
    else:
        return
    # a unit in the message, not a description of one ("m, degrees", "horizontal length")
    unit = f" {p.unit}" if p.unit and "," not in p.unit and "length" not in p.unit else ""
    for which, v in items:
        if not math.isfinite(v):
            raise InputError(f"{p.name}{which}: must be a finite number, got {v}")
        if p.minimum is not None and v < p.minimum:
            raise InputError(f"{p.name}{which}: must be >= {p.minimum:g}{unit}, got {v:g}")
        if p.maximum is not None and v > p.maximum:
            raise InputError(f"{p.name}{which}: must be <= {p.maximum:g}{unit}, got {v:g}")


def options_from(cls: type, spec: AlgorithmSpec, values: Mapping[str, Any], **extra: Any) -> Any:
    """An instance of the science dataclass ``cls`` from the parameters whose default is one
    of its fields (:attr:`Param.source`), with ``extra`` fields (what needs a conversion: a
    parameter whose :class:`Ref` converts, e.g. arcseconds to radians, is given there); the
    other fields keep their defaults.

    >>> spec = AlgorithmSpec("x", "X", "G", "g", "s", "d", (Param("EPSILON", "number", "E",
    ...     Ref("lidar.roof_planes", "RoofPlaneParams", "epsilon")),))
    >>> from lidarphoto.core.lidar.roof_planes import RoofPlaneParams
    >>> options_from(RoofPlaneParams, spec, {"EPSILON": 0.2}, seed=3).epsilon
    0.2
    """
    mapped = [p for p in spec.params if p.source is not None and p.source.name == cls.__name__]
    stray = [f"{p.name} ({p.source})" for p in mapped if not p.source.names(cls)]
    if stray:  # a field read from another class of that name would be silently left out
        raise TypeError(
            f"{spec.name}: parameters {', '.join(stray)} do not name "
            f"{cls.__module__}.{cls.__name__}"
        )
    fields = {
        p.source.field: values[p.name]
        for p in mapped
        if p.source.convert is None and p.name in values
    }
    fields.update(extra)
    return cls(**fields)


def parse_values(spec: AlgorithmSpec, raw: Mapping[str, Any]) -> Values:
    """Every input and output parameter of ``spec`` from ``raw`` (missing -> default).

    Unknown names are refused, so a misspelt parameter never passes silently.
    """
    known = {p.name for p in spec.params}
    unknown = sorted(set(raw) - known)
    if unknown:
        raise InputError(f"{spec.name}: unknown parameter(s) {', '.join(unknown)}")
    out = Values()
    for p in spec.params:
        if p.kind == "sink":
            continue
        value = raw.get(p.name)
        if p.is_output:
            out[p.name] = str(value) if value else None
        elif p.kind == "points" and value is not None and not isinstance(value, str):
            out[p.name] = value  # an object the QGIS adapter made from a layer
        else:
            out[p.name] = parse_value(p, value)
    return out
