"""Start-up stays cheap: the registry and the command line's list of algorithms import no
science and no heavy library, and an algorithm's own help imports only the light modules its
defaults live in (bench/startup.md has the times). Each check runs in a fresh interpreter,
whose ``sys.modules`` is what a user's ``lidarphoto ... --help`` would load."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from lidarphoto.core.jobs import ALGORITHMS

#: Libraries that cost 0.1-1.5 s to import each; none is needed to list or document the
#: algorithms.
HEAVY = ("scipy", "cv2", "laspy", "lazrs", "numba", "pyproj", "osgeo", "rasterio", "dask",
         "distributed", "sklearn")  # fmt: skip
#: The core modules listing the algorithms may import: the registry and the spec language,
#: the messages, and the output set the runner names in its types.
LISTING = {"lidarphoto.core", "lidarphoto.core.errors", "lidarphoto.core.i18n",
           "lidarphoto.core.io", "lidarphoto.core.io.atomic", "lidarphoto.core.io.suffixes",
           "lidarphoto.core.cli"}  # fmt: skip  (io.suffixes: the readers' endings, stdlib only)


def _imported_by(code: str) -> dict:
    """The modules a fresh interpreter holds after ``code``."""
    probe = f"{code}\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"
    run = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         timeout=300)  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    return json.loads(run.stdout.splitlines()[-1])


def _heavy(modules) -> list[str]:
    return sorted(m for m in modules if m.split(".")[0] in HEAVY)


def test_listing_the_algorithms_imports_no_science():
    """The registry, every job's spec and the command line's parser with its list of
    algorithms (what ``lidarphoto --help`` shows)."""
    modules = _imported_by(
        "from lidarphoto.core import jobs\n"
        "specs = [job.SPEC.summary for job in jobs.algorithms()]\n"
        "from lidarphoto.core.cli import build_parser\n"
        "build_parser(with_options=()).format_help()"
    )
    assert _heavy(modules) == []
    assert "numpy" not in modules  # 0.1-0.3 s: the job modules import it where they use it
    core = {m for m in modules if m.startswith("lidarphoto.core")}
    science = sorted(m for m in core - LISTING if not m.startswith("lidarphoto.core.jobs"))
    assert science == [], "listing the algorithms imported the science"


def test_the_top_level_help_reads_no_parameter():
    """``lidarphoto --help`` through main(): the specs with science defaults keep them unread
    (``params`` is made on first use)."""
    probe = (
        "from lidarphoto.core import cli, jobs\n"
        "try:\n    cli.main(['--help'])\nexcept SystemExit:\n    pass\n"
        "print([j.SPEC.name for j in jobs.algorithms() if 'params' in vars(j.SPEC)])"
    )
    run = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         timeout=300)  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    read = run.stdout.splitlines()[-1]
    lazy = [j.SPEC.name for j in ALGORITHMS if "_unresolved" in vars(j.SPEC)]
    assert len(lazy) >= 15  # nearly every spec reads defaults or choices from the science
    assert not any(f"'{name}'" in read for name in lazy), read


@pytest.mark.parametrize("name", sorted(j.SPEC.name for j in ALGORITHMS))
def test_an_algorithms_help_imports_no_heavy_library(name):
    """``lidarphoto <alg> --help``: the parser of that algorithm with every option, default,
    unit and range; the science behind the defaults is light, without numpy
    (its options live in modules such as photo/bundle_options.py)."""
    modules = _imported_by(
        "from lidarphoto.core.cli import build_parser\n"
        f"parser = build_parser(with_options={{{name!r}}})\n"
        "try:\n"
        f"    parser.parse_args([{name!r}, '--help'])\n"
        "except SystemExit:\n"
        "    pass"
    )
    assert _heavy(modules) == []
    assert "numpy" not in modules  # 0.1-0.3 s: the defaults and choices live in light modules


def test_the_runner_and_the_science_are_imported_when_a_job_runs():
    """What the listing leaves out is there once a job runs (the laziness is real)."""
    modules = _imported_by(
        "from lidarphoto.core.jobs import ground_filter\n"
        "from lidarphoto.core.jobs.runner import run_job\n"
        "try:\n"
        "    run_job(ground_filter, {'INPUT': '/nonexistent.laz', 'OUTPUT_CLOUD': '/tmp/x.laz'})\n"
        "except Exception:\n"
        "    pass"
    )
    assert "lidarphoto.core.lidar.ground_filter" in modules
