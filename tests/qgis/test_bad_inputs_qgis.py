"""A representative subset of tests/core/test_bad_inputs.py in real QGIS: the same refusals
reach the user as QgsProcessingException (processing.run) or as a failed qgis_process run,
with the core's words, nothing written and the inputs intact; a cancel from QGIS removes the
temporaries as a stop signal does on the command line."""

from __future__ import annotations

import hashlib
import subprocess
from pathlib import Path

import processing
import pytest
from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight
from qgis.core import QgsProcessingException, QgsProcessingFeedback
from qgis_helpers import QGIS_PROCESS, ROOT

AHN3 = Path(ROOT) / "tests" / "data" / "ahn3" / "ahn3_delft_crop60.laz"


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _files(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


class _CancelWhileWriting(QgsProcessingFeedback):
    """Cancels once the job reports progress past ``at`` percent (the write of the cloud)."""

    def __init__(self, at: float) -> None:
        super().__init__()
        self.at = at
        self.progressChanged.connect(self._check)

    def _check(self, percent: float) -> None:
        if percent > self.at and not self.isCanceled():
            self.cancel()


def test_cancel_while_writing_leaves_no_temporary(provider, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "g.laz").write_bytes(b"the previous result")
    # groundfilter: read 0-30 %, filter 30-60 %, write 60-100 %; cancelled when the filter is
    # done, the write stops before its first chunk, its temporaries already made
    feedback = _CancelWhileWriting(59.5)
    with pytest.raises(QgsProcessingException, match="cancelled while processing the point cloud"):
        processing.run("lidarphoto:groundfilter", {
            "INPUT": str(AHN3), "OUTPUT_CLOUD": str(out / "g.laz"),
            "OUTPUT_DTM": str(out / "dtm.tif"),
        }, feedback=feedback)  # fmt: skip
    assert _files(out) == ["g.laz"]  # no temporary, no DTM
    assert (out / "g.laz").read_bytes() == b"the previous result"


@pytest.mark.parametrize(
    ("params", "words"),
    [
        (
            {"SMRF_CELL_SIZE": 100.0, "SMRF_WINDOW": 100.0},
            r"SMRF_CELL_SIZE: 100 metre is larger than the data's extent \(60 x 59\.99 metre\)",
        ),
        (
            {"CRS": "EPSG:31983"},
            r"the cloud \(header extent\) .* lies outside the area of use of 'SIRGAS 2000 / UTM "
            r"zone 23S'",
        ),
        (
            {"METHOD": 1, "INITIAL_DISTANCE": 3.0, "MAX_DISTANCE": 2.0},
            r"INITIAL_DISTANCE \(3\) must not exceed MAX_DISTANCE \(2\)",
        ),
    ],
    ids=["cell beyond the extent", "CRS of another country", "thresholds in the wrong order"],
)
def test_processing_run_refuses_with_the_core_words(provider, tmp_path, params, words):
    out = tmp_path / "out"
    out.mkdir()
    before = _digest(AHN3)
    with pytest.raises(QgsProcessingException, match=words):
        processing.run(
            "lidarphoto:groundfilter",
            {"INPUT": str(AHN3), "OUTPUT_CLOUD": str(out / "g.laz"), **params},
        )
    assert _files(out) == [] and _digest(AHN3) == before


@pytest.fixture(scope="module")
def flight(tmp_path_factory):
    cfg = FlightConfig(n_buildings=12, n_planes=30, town_size_m=700.0, n_check=3,
                       types=("tie", "line", "lcp"))  # fmt: skip
    sim = simulate_flight(cfg, seed=6)
    return sim, sim.write(tmp_path_factory.mktemp("flight"))


def _qgis_process(args: list[str], env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run(
        [QGIS_PROCESS, *args], env=env, capture_output=True, text=True, timeout=300
    )


def test_qgis_process_refuses_an_implausible_boresight(qp_env, flight, tmp_path):
    """qgis_process exits non-zero with the reason; only the HTML summary (the diagnosis) is
    written."""
    _, paths = flight
    out = tmp_path / "out"
    r = _qgis_process([
        "run", "lidarphoto:boresightcalibration", "--",
        f"CAMERA={paths['camera']}", f"TRAJECTORY={paths['trajectory']}", "CRS=EPSG:28992",
        "LEVER_ARM=0.15,-0.05,-0.6", f"OBSERVATIONS={paths['observations']}",
        f"PLANES={paths['planes']}", f"LINES={paths['lines']}", f"LCPS={paths['lcps']}",
        "SNOOPING=false", "MAX_BORESIGHT=0.05", f"OUTPUT_TABLE={out / 'b.csv'}",
        f"OUTPUT_EO={out / 'eo.csv'}", f"OUTPUT_HTML={out / 'summary.html'}",
        "OUTPUT_RESIDUALS=TEMPORARY_OUTPUT",
    ], qp_env)  # fmt: skip
    text = r.stdout + r.stderr
    assert r.returncode != 0, text[-2000:]
    assert "the boresight calibration failed its checks" in text
    assert "beyond MAX_BORESIGHT 0.05 deg" in text
    assert _files(out) == ["summary.html"]


def test_qgis_process_refuses_an_output_that_is_the_input(qp_env, tmp_path):
    src = tmp_path / "cloud.laz"
    src.write_bytes(AHN3.read_bytes())
    before = _digest(src)
    r = _qgis_process(
        ["run", "lidarphoto:groundfilter", "--", f"INPUT={src}", f"OUTPUT_CLOUD={src}"], qp_env
    )
    text = r.stdout + r.stderr
    assert r.returncode != 0, text[-2000:]
    assert "OUTPUT_CLOUD is the input INPUT" in text
    assert _digest(src) == before and _files(tmp_path) == ["cloud.laz", "plugins", "qgis-config"]
