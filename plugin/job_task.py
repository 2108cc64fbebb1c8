"""One core job run in the QGIS task manager for the picking dock (calibration, resection,
bundle adjustment): the dock's inputs written as the files the job reads, then the job, in a
worker thread; the dock is told in the GUI thread. :class:`JobController` is what the dock's
three Run buttons share: one task at a time, the failure shown, the result drawn."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from types import ModuleType

from qgis.core import QgsApplication, QgsTask
from qgis.PyQt import sip
from qgis.PyQt.QtCore import QCoreApplication, QObject, pyqtSignal

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


class JobController(QObject):
    """A Run button of the picking dock: one :class:`JobTask` at a time in the QGIS task
    manager; a failure (or cancel) shown in the panel and the dock's message bar, a result
    handed to :meth:`_show`, then the observations redrawn.

    Subclasses give :meth:`_show` and, where the job's data can be empty, :meth:`_usable`;
    their start method checks :meth:`_busy` and its inputs, then calls :meth:`_launch`. The
    words shown are the subclass's (``self.tr`` there: its own translation context).

    Signals
    -------
    finished(bool)
        The task ended; on failure :attr:`error` says why.
    """

    finished = pyqtSignal(bool)

    def __init__(self, dock, panel) -> None:
        super().__init__(dock)
        self.dock, self.panel = dock, panel
        self.task: JobTask | None = None
        self.params: dict = {}
        self.error = ""
        self._failure_texts = ("", "{}")

    def tr(self, text: str) -> str:
        # the context lupdate gives the subclass's self.tr("...")
        return QCoreApplication.translate(type(self).__name__, text)

    @property
    def running(self) -> bool:
        return self.task is not None

    def _usable(self, result: JobResult) -> bool:
        """Whether the job's result holds what :meth:`_show` needs."""
        return True

    def _show(self, result: JobResult) -> None:
        """Keep and show a successful result (the GUI thread)."""
        raise NotImplementedError

    def _busy(self, text: str) -> bool:
        """True (with the message ``text``) when a task of this button is running."""
        if self.running:
            self.dock.message(text)
        return self.running

    def _launch(self, description: str, job: ModuleType, params: dict, output_key: str,
                write_inputs: Callable[[], None], cancelled: str, failed: str) -> bool:  # fmt: skip
        """Start the job in the task manager (see :class:`JobTask`); True. ``cancelled`` and
        ``failed`` (``{}``: the error) are the words shown if it does not succeed."""
        self.params, self.error = params, ""
        self._failure_texts = (cancelled, failed)
        self.panel.set_running(True)
        self.task = JobTask(description, job, params, output_key, write_inputs, self._done)
        QgsApplication.taskManager().addTask(self.task)
        return True

    def _done(self, ok: bool, task: JobTask) -> None:
        if sip.isdeleted(self):  # the dock was closed and deleted meanwhile
            return
        self.task = None
        self.error = task.error
        dock, panel = self.dock, self.panel
        panel.set_running(False)
        if not ok or task.result is None or not self._usable(task.result):
            cancelled, failed = self._failure_texts
            if task.cancelled or task.isCanceled():  # (also: cancelled before it started)
                text = cancelled
            else:
                text = failed.format(task.error)
            panel.result_label.setText(text)
            dock.message(text, warning=True)
            self.finished.emit(False)
            return
        self._show(task.result)
        dock.picking.draw_observations()
        dock.picking.fill_table()
        self.finished.emit(True)
