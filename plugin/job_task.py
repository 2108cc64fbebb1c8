"""One core job run in the QGIS task manager for the picking dock (calibration, resection,
bundle adjustment): the dock's inputs written as the files the job reads, then the job, in a
worker thread; the dock is told in the GUI thread."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from types import ModuleType

from qgis.core import QgsTask

from ..core.errors import Cancelled
from ..core.jobs.runner import JobResult, run_job


class JobTask(QgsTask):
    """Run ``write_inputs()`` then ``run_job(job, params)``; ``result`` or ``error`` afterwards.

    ``output_key`` names the parameter whose folder is made first; ``done(ok, task)`` is
    called in the GUI thread. Every failure ends in :attr:`error` (shown in the dock), none
    is raised; a cancel sets :attr:`cancelled`.
    """

    def __init__(
        self,
        description: str,
        job: ModuleType,
        params: dict,
        output_key: str,
        write_inputs: Callable[[], None],
        done: Callable[[bool, JobTask], None],
    ) -> None:
        super().__init__(description)
        self.job, self.params, self.output_key = job, params, output_key
        self.write_inputs, self.done = write_inputs, done
        self.result: JobResult | None = None
        self.error = ""
        self.cancelled = False

    def run(self) -> bool:  # a worker thread: no widget here
        try:
            Path(self.params[self.output_key]).parent.mkdir(parents=True, exist_ok=True)
            self.write_inputs()
            self.result = run_job(
                self.job,
                self.params,
                progress=lambda f: self.setProgress(100.0 * f),
                should_stop=self.isCanceled,
            )
        except Cancelled as exc:
            self.cancelled, self.error = True, str(exc)
            return False
        except Exception as exc:  # every failure is reported in the dock, none is raised
            self.error = str(exc) or type(exc).__name__
            return False
        return True

    def finished(self, ok: bool) -> None:  # the GUI thread
        self.done(ok, self)
