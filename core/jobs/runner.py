"""Run a job the same way from every view: values checked, outputs staged, committed together.

The QGIS algorithm and the command line both call :func:`run_job`. It parses and checks every
value against the job's spec (naming the parameter), refuses an output that would overwrite a
file the job reads (every file and folder input, a folder standing for the files the job
reads from it: :func:`~lidarphoto.core.io.atomic.check_outputs`) before anything is read,
hands the job an :class:`~lidarphoto.core.io.atomic.OutputSet` to write into, and moves the
outputs into place only when the job returned.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any

from ..io.atomic import OutputSet
from .spec import FILE_KINDS, AlgorithmSpec, Values, parse_values

Progress = Callable[[float], None]
ShouldStop = Callable[[], bool]


@dataclass
class JobResult:
    """What a job returns.

    ``results`` holds the values of the spec's :class:`~.spec.Result` entries; ``lines`` the
    summary the command line prints (QGIS logs it); ``data`` the core objects the QGIS layers
    and the picking dock are made from; ``stdout`` text the command line prints instead of a
    file the user did not name.
    """

    results: dict[str, Any] = field(default_factory=dict)
    lines: list[str] = field(default_factory=list)
    data: Any = None
    stdout: str = ""
    #: exit status of the command line (e.g. 3: a block processed incompletely)
    exit_code: int = 0


def input_files(spec: AlgorithmSpec, values: Mapping[str, Any]) -> dict[str, Any]:
    """The input files and folders named in ``values`` (what no output may overwrite)."""
    return {
        p.name: values[p.name]
        for p in spec.inputs
        if (p.kind in (*FILE_KINDS, "points") and isinstance(values.get(p.name), str))
        or (p.kind == "files" and values.get(p.name))
    }


def folder_suffixes(spec: AlgorithmSpec) -> dict[str, tuple[str, ...]]:
    """The file endings each input reads from a folder (``Param.suffixes``; every file when
    an input declares none)."""
    return {p.name: p.suffixes for p in spec.inputs if p.suffixes}


def run_job(
    job: ModuleType,
    raw: Mapping[str, Any],
    progress: Progress | None = None,
    should_stop: ShouldStop | None = None,
) -> JobResult:
    """Run ``job`` (a module of core/jobs with ``SPEC`` and ``run``) on the raw values."""
    spec: AlgorithmSpec = job.SPEC
    values: Values = parse_values(spec, raw)
    # a folder output holds files the job commits itself (core/jobs/<job>.py)
    outputs = {
        p.name: values.get(p.name) for p in spec.outputs if p.kind not in ("sink", "folder_out")
    }
    with OutputSet(outputs, input_files(spec, values), folder_suffixes(spec)) as out:
        result = job.run(values, out, progress=progress, should_stop=should_stop)
        out.commit()
    return result


def stages(progress: Progress | None, *weights: float) -> list[Progress | None]:
    """Split one progress callback into consecutive stages of the given weights.

    >>> seen = []
    >>> a, b = stages(seen.append, 1, 3)
    >>> a(1.0); b(0.5)
    >>> seen
    [0.25, 0.625]
    """
    if progress is None:
        return [None] * len(weights)
    total = float(sum(weights))
    out: list[Progress | None] = []
    start = 0.0
    for w in weights:
        lo, span = start / total, w / total

        def stage(f: float, lo: float = lo, span: float = span) -> None:
            progress(lo + span * min(max(float(f), 0.0), 1.0))

        out.append(stage)
        start += w
    return out
