"""Reader of the solver's history.csv (pipeline/formats.md §4): one numpy array per column."""
from __future__ import annotations

import re

import numpy as np

from .errors import PostprocessError

# The columns formats.md §4 promises, in its order, with the ones that hold counts.
HISTORY_COLUMNS = ("step", "time", "dt", "iterations", "rejected", "kinetic_energy", "strain_energy",
                   "external_work", "damping_work", "broken_bonds", "wall_time")
INTEGER_COLUMNS = frozenset(("step", "iterations", "rejected", "broken_bonds"))


def _parse_int(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        value = float(text)  # tolerate "12.0" or "1e+06"; a fraction is an error
        if not value.is_integer():
            raise ValueError(f"'{text}' is not a whole number") from None
        return int(value)


def read_history(path: str) -> dict[str, np.ndarray]:
    """The columns of history.csv by name: int64 arrays for counts, float64 for the rest.

    Every column of formats.md §4 must be in the header (extra columns are read too, as float64).
    A row with the wrong number of fields or a field that is not a number is an error naming
    the file and the line. Blank lines are skipped; "nan" and "inf" are numbers (a run that blew
    up still gets its figures).
    """
    try:
        with open(path, encoding="utf-8") as stream:
            lines = stream.read().splitlines()
    except FileNotFoundError:
        raise PostprocessError(f"{path}: no such file; run the solver first (make case=<case>)") from None
    except (OSError, UnicodeDecodeError) as error:
        raise PostprocessError(f"{path}: cannot read: {error}") from None

    header_index = next((i for i, line in enumerate(lines) if line.strip()), None)
    if header_index is None:
        raise PostprocessError(f"{path}: empty file, expected a header line "
                               f"({','.join(HISTORY_COLUMNS)}); was the solver interrupted?")
    names = [name.strip() for name in lines[header_index].split(",")]
    missing = [name for name in HISTORY_COLUMNS if name not in names]
    if missing:
        raise PostprocessError(f"{path}:{header_index + 1}: header lacks column(s) {', '.join(missing)}; "
                               f"expected {','.join(HISTORY_COLUMNS)} (pipeline/formats.md §4)")
    duplicates = sorted({name for name in names if names.count(name) > 1})
    if duplicates:
        raise PostprocessError(f"{path}:{header_index + 1}: column(s) {', '.join(duplicates)} appear twice")

    columns: list[list] = [[] for _ in names]
    parsers = [_parse_int if name in INTEGER_COLUMNS else float for name in names]
    for number, line in enumerate(lines[header_index + 1:], start=header_index + 2):
        if not line.strip():
            continue
        fields = line.split(",")
        if len(fields) != len(names):
            raise PostprocessError(f"{path}:{number}: {len(fields)} fields, the header has {len(names)}: "
                                   f"'{line.strip()}'")
        for name, parse, field, column in zip(names, parsers, fields, columns):
            try:
                column.append(parse(field.strip()))
            except ValueError:
                raise PostprocessError(f"{path}:{number}: column '{name}': '{field.strip()}' is not "
                                       f"{'a whole number' if parse is _parse_int else 'a number'}") from None
    if not columns[0]:
        raise PostprocessError(f"{path}: a header but no data rows; was the solver interrupted "
                               f"before its first step?")
    return {name: np.asarray(column, dtype=np.int64 if parse is _parse_int else np.float64)
            for name, parse, column in zip(names, parsers, columns)}


def vector_column_names(history: dict, prefix: str) -> list[str]:
    """The <name>s that have all three columns <prefix>_<name>_fx, _fy, _fz in history.csv, in
    column order (formats.md §4: indenter reactions, reactions of node sets)."""
    column = re.compile(rf"^{re.escape(prefix)}_([A-Za-z_][A-Za-z0-9_]*)_f([xyz])$")
    found: dict[str, set] = {}
    for name in history:
        match = column.match(name)
        if match:
            found.setdefault(match.group(1), set()).add(match.group(2))
    return [name for name, axes in found.items() if axes == {"x", "y", "z"}]
