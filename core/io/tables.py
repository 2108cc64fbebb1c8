"""Delimited text tables with a header row, read with errors that name file, row and column.

Rows are numbered as a spreadsheet shows them: the header is row 1, the first data row is 2.
The delimiter (comma, semicolon, tab or whitespace) is detected from the header line. Lines
starting with ``#`` are comments.
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Callable, Hashable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, Union, overload

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .atomic import atomic_write

PathLike = Union[str, "os.PathLike[str]"]


@dataclass(frozen=True)
class Table:
    """Raw text cells of a table: ``columns`` in file order, ``rows`` with their line numbers."""

    path: str
    columns: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    line_numbers: tuple[int, ...]

    def __len__(self) -> int:
        return len(self.rows)


def read_table(path: PathLike) -> Table:
    """Read a delimited table; raise :class:`InputError` for a missing, empty or ragged file."""
    p = Path(path)
    if not p.is_file():
        raise InputError("file not found", path=str(p))
    try:
        text = p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(f"not a UTF-8 text table ({exc.reason})", path=str(p)) from exc
    lines = [
        (i + 1, line)
        for i, line in enumerate(text.splitlines())
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not lines:
        raise InputError("the table is empty (no header row)", path=str(p))
    header_no, header = lines[0]
    delimiter = _detect_delimiter(header)
    parsed = _split(lines, delimiter)
    columns = tuple(c.strip() for c in parsed[0])
    if any(not c for c in columns):
        raise InputError("the header has an empty column name", path=str(p), row=header_no)
    seen: set[str] = set()
    for c in columns:
        key = normalise(c)
        if key in seen:
            raise InputError(f"column '{c}' appears twice in the header", path=str(p), row=1)
        seen.add(key)
    rows = []
    numbers = []
    for (number, _), cells in zip(lines[1:], parsed[1:]):
        if len(cells) != len(columns):
            raise InputError(
                f"has {len(cells)} values but the header has {len(columns)} columns",
                path=str(p),
                row=number,
            )
        rows.append(tuple(c.strip() for c in cells))
        numbers.append(number)
    if not rows:
        raise InputError("the table has a header but no data rows", path=str(p))
    return Table(str(p), columns, tuple(rows), tuple(numbers))


def normalise(name: str) -> str:
    return name.strip().lower().replace(" ", "_").replace("-", "_")


@overload
def find_column(
    table: Table, aliases: Sequence[str], *, required: Literal[True] = ..., what: str | None = ...
) -> int: ...


@overload
def find_column(
    table: Table, aliases: Sequence[str], *, required: bool, what: str | None = ...
) -> int | None: ...


def find_column(
    table: Table, aliases: Sequence[str], *, required: bool = True, what: str | None = None
) -> int | None:
    """Index of the first column whose normalised name is one of ``aliases``."""
    names = [normalise(c) for c in table.columns]
    for alias in aliases:
        if alias in names:
            return names.index(alias)
    if required:
        raise InputError(
            f"no column for {what or aliases[0]} (accepted names: {', '.join(aliases)}; "
            f"found: {', '.join(table.columns)})",
            path=table.path,
        )
    return None


def float_column(
    table: Table, index: int, *, finite: bool = True, allow_empty: bool = False
) -> NDArray[np.float64]:
    """Parse one column as floats; the error names the row and the column.

    With ``allow_empty`` an empty cell becomes NaN (for optional values such as time).
    """
    out = np.empty(len(table), dtype=np.float64)
    name = table.columns[index]
    for k, (row, number) in enumerate(zip(table.rows, table.line_numbers)):
        cell = row[index]
        if allow_empty and not cell:
            out[k] = np.nan
            continue
        try:
            value = float(cell)
        except ValueError:
            raise InputError(
                f"'{cell}' is not a number", path=table.path, row=number, column=name
            ) from None
        if finite and not math.isfinite(value):
            raise InputError(
                f"'{cell}' is not a finite number", path=table.path, row=number, column=name
            )
        out[k] = value
    return out


def text_column(table: Table, index: int, *, nonempty: bool = True) -> tuple[str, ...]:
    values = tuple(row[index] for row in table.rows)
    if nonempty:
        for value, number in zip(values, table.line_numbers):
            if not value:
                raise InputError(
                    "empty value", path=table.path, row=number, column=table.columns[index]
                )
    return values


def unique_ids(table: Table, index: int) -> tuple[str, ...]:
    """A text column whose values must be unique (e.g. image ids)."""
    values = text_column(table, index)
    first: dict[Hashable, int] = {}
    for value, number in zip(values, table.line_numbers):
        note_unique(first, value, f"'{value}'", table, number, index)
    return values


def note_unique(
    first: dict[Hashable, int], value: Hashable, label: str, table: Table, row: int, index: int
) -> None:
    """Record that ``value`` stands in file row ``row`` of column ``index``; InputError naming
    ``label`` and the row it first stood in when it was seen before (``first`` maps value to row).
    """
    if value in first:
        raise InputError(
            f"{label} already appears in row {first[value]}",
            path=table.path,
            row=row,
            column=table.columns[index],
        )
    first[value] = row


def choice_column(table: Table, index: int, allowed: Sequence[str], what: str) -> tuple[str, ...]:
    """A text column whose values (stripped, lower case) must be among ``allowed``; ``what``
    names such a value in the error ("a role": "'x' is not a role (control, check)")."""
    values = tuple(v.strip().lower() for v in text_column(table, index))
    for value, number in zip(values, table.line_numbers):
        if value not in allowed:
            raise InputError(
                f"'{value}' is not {what} ({', '.join(allowed)})",
                path=table.path,
                row=number,
                column=table.columns[index],
            )
    return values


def refuse_rows(
    table: Table, bad: NDArray[np.bool_], index: int | None, message: Callable[[int], str]
) -> None:
    """InputError at the first row where ``bad`` is True, naming the file, that row and column
    ``index`` (none where None), with the text ``message(k)`` of its position ``k`` (0-based)
    among the table's rows; nothing where no row is bad.

    >>> t = Table("p.csv", ("id", "h"), (("a", "1"), ("b", "-2")), (2, 3))
    >>> h = np.array([1.0, -2.0])
    >>> try:
    ...     refuse_rows(t, h < 0, 1, lambda k: f"{h[k]:g} m is below ground")
    ... except InputError as exc:
    ...     print(exc)
    p.csv, row 3, column 'h': -2 m is below ground
    """
    rows = np.flatnonzero(bad)
    if rows.size:
        k = int(rows[0])
        raise InputError(
            message(k),
            path=table.path,
            row=table.line_numbers[k],
            column=None if index is None else table.columns[index],
        )


def sigma_column(
    table: Table, aliases: Sequence[str], default: float = 0.0
) -> NDArray[np.float64] | None:
    """The optional standard-deviation column named by one of ``aliases`` (in its own unit),
    None where the table has none; an empty cell is ``default``.

    Raises
    ------
    InputError
        A value that is not a finite number or is negative, naming the file, row and column.

    >>> t = Table("p.csv", ("id", "sigma"), (("a", "0.5"), ("b", "")), (2, 3))
    >>> sigma_column(t, ("sigma",), 0.1).tolist()
    [0.5, 0.1]
    >>> sigma_column(t, ("s",)) is None
    True
    """
    col = find_column(table, aliases, required=False)
    if col is None:
        return None
    values = float_column(table, col, allow_empty=True)
    values[np.isnan(values)] = default
    refuse_rows(
        table, values < 0, col, lambda k: f"a standard deviation cannot be negative ({values[k]:g})"
    )
    return values


def check_covariance(cov: NDArray[np.float64], table: Table, k: int, what: str) -> None:
    """Refuse (naming the file and row) a covariance matrix that is not positive
    semi-definite: a negative variance or an impossible correlation.

    >>> t = Table("p.csv", ("id",), (("1",),), (2,))
    >>> try:
    ...     check_covariance(np.diag([1.0, -1e-3]), t, 0, "covariance of (a, b)")
    ... except InputError as exc:
    ...     print(exc)  # doctest: +NORMALIZE_WHITESPACE
    p.csv, row 2: the covariance of (a, b) is not positive semi-definite (smallest
    eigenvalue -0.001)
    """
    scale = max(1.0, float(np.abs(cov).max()))
    low = float(np.linalg.eigvalsh(cov).min())
    if not np.isfinite(low) or low < -1e-12 * scale:
        raise InputError(
            f"the {what} is not positive semi-definite (smallest eigenvalue {low:.3g})",
            path=table.path,
            row=table.line_numbers[k],
        )


def check_integers(
    table: Table, values: NDArray[np.float64], index: int, what: str = "an integer"
) -> None:
    """Refuse (naming the file, row and column ``index``) the first of ``values``, read from
    that column, that is not a whole number."""
    refuse_rows(
        table,
        values != np.round(values),
        index,
        lambda k: f"'{table.rows[k][index]}' is not {what}",
    )


def unique_integer_ids(table: Table, values: NDArray[np.float64], index: int) -> list[int]:
    """The id column as integers, each once; errors name the file, row and column."""
    check_integers(table, values, index, "an integer id")
    seen: dict[Hashable, int] = {}
    out = []
    for value, number in zip(values, table.line_numbers):
        key = int(value)
        note_unique(seen, key, f"id {key}", table, number, index)
        out.append(key)
    return out


def number(value: Any) -> str:
    """A number as the core writes it in every table: the shortest text that reads back to the
    same double (``repr``: full precision, no rounding, whatever the unit), empty when it is not
    finite (no value).

    >>> number(0.1 + 0.2), number(1.5e-6), number(float("nan")), number(np.float32(0.1))
    ('0.30000000000000004', '1.5e-06', '', '0.10000000149011612')
    """
    v = float(value)
    return repr(v) if math.isfinite(v) else ""


def _cell(value: object) -> object:
    """A float cell through :func:`number`; anything else as it is."""
    return number(value) if isinstance(value, (float, np.floating)) else value


def write_csv_atomic(
    path: PathLike,
    columns: Sequence[str],
    rows: Iterable[Sequence[object]],
    comments: Sequence[str] = (),
) -> None:
    """Write a CSV through :func:`~lidarphoto.core.io.atomic.atomic_write`: a temporary file in
    the same folder moved into place, so a crash never leaves a half-written file at ``path``.

    Float cells are written with :func:`number` (full precision; empty when not finite).
    ``comments`` are written before the header as ``# text`` lines (the readers of this
    package skip them), e.g. a warning the user must not miss.
    """
    with atomic_write(path, newline="") as fh:
        for line in comments:
            fh.write("# " + " ".join(str(line).split()) + "\n")
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(columns)
        writer.writerows([_cell(v) for v in row] for row in rows)


def _detect_delimiter(header: str) -> str | None:
    for delimiter in (",", ";", "\t"):
        if delimiter in header:
            return delimiter
    return None  # whitespace


def _split(lines: list[tuple[int, str]], delimiter: str | None) -> list[list[str]]:
    if delimiter is None:
        return [line.split() for _, line in lines]
    return list(csv.reader((line for _, line in lines), delimiter=delimiter))
