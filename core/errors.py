"""Typed errors of the core. The QGIS adapter turns them into QgsProcessingException."""

from __future__ import annotations

from collections.abc import Callable, Sequence


class LidarPhotoError(Exception):
    """Base class of every error the core raises on purpose."""


class InputError(LidarPhotoError, ValueError):
    """Bad user input: names the file, row (1-based, header is row 1) and column when known."""

    def __init__(
        self,
        message: str,
        *,
        path: str | None = None,
        row: int | None = None,
        column: str | None = None,
    ) -> None:
        self.path = path
        self.row = row
        self.column = column
        where = []
        if path is not None:
            where.append(str(path))
        if row is not None:
            where.append(f"row {row}")
        if column is not None:
            where.append(f"column '{column}'")
        super().__init__(f"{': '.join([', '.join(where), message]) if where else message}")


class CrsError(InputError):
    """A coordinate reference system is missing, unknown or unsuitable."""


class Cancelled(LidarPhotoError):
    """The user cancelled a long computation (raised when ``should_stop()`` returns True)."""


def stop_if_asked(should_stop: Callable[[], bool] | None, doing: str) -> None:
    """Raise :class:`Cancelled` ("cancelled while <doing>") when ``should_stop()`` says so."""
    if should_stop is not None and should_stop():
        raise Cancelled(f"cancelled while {doing}")


def use_compiled(backend: str, available: bool) -> bool:
    """Resolve a ``backend`` argument (``"auto"``, ``"numba"`` or ``"numpy"``) of a function
    with a numba kernel: True to run the compiled kernel. ``available``: numba imported.

    >>> use_compiled("auto", False), use_compiled("numpy", True), use_compiled("auto", True)
    (False, False, True)
    """
    if backend not in ("auto", "numba", "numpy"):
        raise InputError(f"backend must be 'auto', 'numba' or 'numpy', got {backend!r}")
    if backend == "numba" and not available:
        raise InputError(
            "backend 'numba' asked for, but numba is not installed (pip install numba)"
        )
    return available and backend != "numpy"


class AdjustmentError(LidarPhotoError):
    """A least-squares adjustment could not produce trustworthy numbers."""


class NotObservableError(AdjustmentError):
    """The normal equations are singular or ill-conditioned.

    ``parameters`` names the parameters that take part in the (near) null space, i.e. those
    that the observations cannot determine; ``null_vectors`` holds the null-space directions
    (columns, in the order of the adjustment's parameter vector).
    """

    def __init__(
        self,
        message: str,
        parameters: Sequence[str] = (),
        null_vectors: object = None,
        condition_number: float | None = None,
    ) -> None:
        self.parameters = list(parameters)
        self.null_vectors = null_vectors
        self.condition_number = condition_number
        super().__init__(message)


class DiagnosedNotObservable(NotObservableError):
    """A :class:`NotObservableError` explained: ``diagnosis`` holds sentences that say what
    would make the parameters observable (appended to the message)."""

    def __init__(self, cause: NotObservableError, diagnosis: list[str]) -> None:
        self.diagnosis = diagnosis
        super().__init__(
            f"{cause} -- diagnosis: " + " ".join(diagnosis),
            cause.parameters,
            cause.null_vectors,
            cause.condition_number,
        )


class ConvergenceError(AdjustmentError):
    """An iterative adjustment did not converge within its iteration limit."""
