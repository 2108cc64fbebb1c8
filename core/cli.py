"""Command line ``lidarphoto`` (also ``python -m lidarphoto``): the processing algorithms
without QGIS, for batch work.

Every subcommand is generated from its job's parameter spec (:mod:`core.jobs`): subcommands
carry the algorithm ids of the QGIS toolbox (``lidarphoto:trajectorytoeo`` ->
``lidarphoto trajectorytoeo``) and options carry its parameter names, lower-cased with dashes
(``LEVER_ARM`` -> ``--lever-arm``), with the same value formats and defaults. Layer outputs
exist only in QGIS; their content is in the file outputs.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import signal
import sys
import threading
from collections.abc import Callable, Collection, Iterator, Sequence

from . import __version__, i18n
from .errors import Cancelled, LidarPhotoError
from .jobs import algorithms
from .jobs.runner import run_job
from .jobs.spec import TR_CONTEXT, AlgorithmSpec, Param, facts_line
from .jobs.translate import context_of, translate_spec

_METAVAR = {
    "file": "FILE",
    "raster": "FILE",
    "pointcloud": "FILE",
    "surface": "FILE",
    "table": "CSV",
    "points": "CSV",
    "crs": "CRS",
    "number": "NUMBER",
    "integer": "INT",
    "boolean": "BOOL",
    "string": "TEXT",
    "field": "COLUMN",
    "file_out": "FILE",
    "raster_out": "FILE",
    "files": "PATH",
    "folder_out": "FOLDER",
}


#: Signals that end a run like Ctrl+C does: the outputs' temporaries are removed first.
_STOP_SIGNALS = tuple(
    getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name)
)


class Terminated(BaseException):
    """A stop signal (SIGTERM, SIGHUP) turned into an exception, so that every ``finally``
    and the output set's clean-up run before the process exits (not an ``Exception``: the
    core's handlers of reading errors must not take it for a bad file)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum

    @property
    def name(self) -> str:
        return signal.Signals(self.signum).name


@contextlib.contextmanager
def stop_signals_raise() -> Iterator[None]:
    """Within the block, SIGTERM and SIGHUP raise :class:`Terminated` (once: a second signal
    during the clean-up is ignored); the previous handlers come back afterwards. Only the
    main thread can set handlers; elsewhere this does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    fired: list[int] = []

    def handler(signum: int, frame: object) -> None:
        if not fired:
            fired.append(signum)
            raise Terminated(signum)

    previous = {s: signal.signal(s, handler) for s in _STOP_SIGNALS}
    try:
        yield
    finally:
        for s, old in previous.items():
            signal.signal(s, old)


def _exit_now(code: int) -> None:
    """End the process with ``code`` now, after a stop signal: the run has cleaned up (its
    temporaries removed, its cluster's workers ended), and what the interpreter's exit would
    still do takes seconds a stopping service does not wait for (distributed's exit hook
    gracefully closes a cluster that was still starting; the teardown of numba, dask and
    GDAL). Child processes still running (workers of a cluster being started) are killed
    first; any started after that end with this process (distributed's workers watch a pipe
    from their parent)."""
    import multiprocessing
    import os

    children = multiprocessing.active_children()
    for child in children:
        child.kill()
    for child in children:
        child.join(1.0)
    logging.shutdown()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    os._exit(code)


def _option_help(
    p: Param, spec: AlgorithmSpec | None = None, t: Callable[[str], str] | None = None
) -> str:
    """label; help; default, unit and valid range (the same facts as the QGIS help); ``t``
    translates the fixed words of the facts."""
    bits = [p.label]
    if p.help and p.help != p.label:
        bits.append(p.help)
    facts = facts_line(p, spec, t) if t is not None else facts_line(p, spec)
    if p.kind == "enum":
        many = " (a comma list)" if p.multiple else ""
        facts += f" (or their index){many}"
    bits.append(facts)
    return "; ".join(bits).replace("%", "%%")


def _add_algorithm(
    sub: argparse._SubParsersAction,
    spec: AlgorithmSpec,
    job: object,
    lang: str = "en",
    options: bool = True,
) -> None:
    """The subcommand of ``spec``; without ``options`` only its name and summary (what the
    list of algorithms shows: the parameters, read from the science, are not needed)."""
    if not options:
        sub.add_parser(spec.name, help=_summary(spec, lang)).set_defaults(job=job)
        return
    if lang != "en":  # the help in the user's language (names and options stay)
        table = i18n.catalogue(lang)
        spec = translate_spec(spec, lambda ctx, text: table.get((ctx, text), text))
    parser = sub.add_parser(
        spec.name,
        help=spec.summary,
        description=spec.help_text(i18n.translator(TR_CONTEXT, lang)),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    for p in spec.params:
        if p.kind == "sink":  # layers: QGIS only
            continue
        help_words = i18n.translator(TR_CONTEXT, lang)
        kwargs: dict = {"dest": p.name, "default": None, "help": _option_help(p, spec, help_words)}
        if p.kind == "boolean":
            kwargs.update(nargs="?", const="true", metavar="true|false")
        elif p.kind == "enum":
            kwargs["metavar"] = "|".join(p.options) if len(p.options) <= 4 else "NAME"
        elif p.kind == "numbers":
            kwargs["metavar"] = ",".join(["N"] * p.count) if p.count <= 4 else f"{p.count}xN"
        elif p.kind == "files":
            kwargs.update(nargs="+", metavar="PATH")
        else:
            kwargs["metavar"] = _METAVAR.get(p.kind, "VALUE")
        if p.required:
            kwargs["required"] = True
        parser.add_argument(p.option, **kwargs)
    parser.set_defaults(job=job)


def _summary(spec: AlgorithmSpec, lang: str) -> str:
    if lang == "en":
        return spec.summary
    return i18n.catalogue(lang).get((context_of(spec), spec.summary), spec.summary)


def build_parser(
    lang: str = "en", with_options: Collection[str] | None = None
) -> argparse.ArgumentParser:
    """The parser; ``lang`` (a catalogue of :mod:`core.i18n`, e.g. ``pt_BR``) translates the
    algorithms' help. ``with_options``: the algorithms whose options are added (None: all);
    the others have their name and summary only, so that the command line reads the
    parameters (and imports the science behind their defaults) of the algorithm it runs
    alone."""
    parser = argparse.ArgumentParser(prog="lidarphoto", description=__doc__.split("\n\n")[0])
    parser.add_argument("--version", action="version", version=f"lidarphoto {__version__}")
    parser.add_argument(
        "-v",
        "--verbose",
        action="count",
        default=0,
        help="log progress to stderr; -vv also the details (e.g. every rejected candidate)",
    )
    parser.add_argument(
        "--lang",
        metavar="LANG",
        help="language of the help and the HTML reports (en, "
        + ", ".join(i18n.available_languages())
        + "; default: from LANG/LC_ALL)",
    )
    sub = parser.add_subparsers(dest="algorithm", metavar="ALGORITHM", required=True)
    for job in algorithms():
        name = job.SPEC.name
        _add_algorithm(sub, job.SPEC, job, lang, with_options is None or name in with_options)
    return parser


def _language(argv: Sequence[str]) -> str:
    """The --lang option (``--lang pt_BR`` or ``--lang=pt_BR``) before the algorithm, else the
    environment's language."""
    for k, arg in enumerate(argv):
        if arg == "--lang" and k + 1 < len(argv):
            return i18n.normalise_language(argv[k + 1])
        if arg.startswith("--lang="):
            return i18n.normalise_language(arg.split("=", 1)[1])
        if not arg.startswith("-"):
            break
    return i18n.language_from_env()


def _algorithm(argv: Sequence[str]) -> str:
    """The algorithm named on the command line (the first word that is neither a global
    option nor the value of --lang), "" when there is none."""
    k = 0
    while k < len(argv):
        arg = argv[k]
        if arg == "--lang":
            k += 2
            continue
        if not arg.startswith("-"):
            return arg
        k += 1
    return ""


#: GDAL's block cache for the command line, MB (GDAL's default, 5 % of the RAM, holds the
#: blocks of a large raster being written until it is full: 1.6 GB for a 196 Mpx orthophoto)
GDAL_CACHE_MB = "256"


def _progress_bar(job):
    """A text progress bar on stderr for the jobs that ask for one (``CLI_PROGRESS``)."""
    if not getattr(job, "CLI_PROGRESS", False):
        return None
    shown = [-1]

    def bar(fraction: float) -> None:
        percent = int(100 * min(max(fraction, 0.0), 1.0))
        if percent != shown[0]:
            shown[0] = percent
            done = percent * 40 // 100
            end = "\n" if percent == 100 else ""
            sys.stderr.write(f"\r[{'#' * done}{'.' * (40 - done)}] {percent:3d} %{end}")
            sys.stderr.flush()

    return bar


def main(argv: Sequence[str] | None = None) -> int:
    """The command line: ``argv`` (default ``sys.argv[1:]``) run, its exit status returned.
    Called without ``argv`` (the ``lidarphoto`` command, ``python -m lidarphoto``), a run
    stopped by a signal ends the process at once after its message (:func:`_exit_now`)."""
    import os

    entry = argv is None
    argv = sys.argv[1:] if argv is None else list(argv)
    lang = i18n.set_language(_language(argv))
    args = build_parser(lang, with_options={_algorithm(argv)}).parse_args(argv)
    os.environ.setdefault("GDAL_CACHEMAX", GDAL_CACHE_MB)  # read by GDAL at its first use
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    if args.verbose >= 2:  # the toolkit's details, not those of the libraries it uses
        logging.getLogger(__name__.split(".")[0]).setLevel(logging.DEBUG)
    spec: AlgorithmSpec = args.job.SPEC
    raw = {
        p.name: getattr(args, p.name)
        for p in spec.params
        if p.kind != "sink" and getattr(args, p.name) is not None
    }
    try:
        with stop_signals_raise():
            result = run_job(args.job, raw, progress=_progress_bar(args.job))
    except Terminated as exc:
        print(
            f"lidarphoto {args.algorithm}: stopped by {exc.name}; nothing was written",
            file=sys.stderr,
        )
        if entry:
            _exit_now(128 + exc.signum)
        return 128 + exc.signum
    except Cancelled as exc:
        print(f"lidarphoto {args.algorithm}: {exc}", file=sys.stderr)
        return 130
    except KeyboardInterrupt:
        print(f"lidarphoto {args.algorithm}: interrupted; nothing was written", file=sys.stderr)
        return 130
    except LidarPhotoError as exc:
        print(f"lidarphoto {args.algorithm}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"lidarphoto {args.algorithm}: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except MemoryError:
        print(
            f"lidarphoto {args.algorithm}: error: out of memory; nothing was written (use a "
            "coarser cell or a smaller input)",
            file=sys.stderr,
        )
        return 2
    if result.stdout:
        sys.stdout.write(result.stdout)
    for line in result.lines:
        print(line)
    return result.exit_code
