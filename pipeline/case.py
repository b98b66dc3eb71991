"""Read a case file: YAML with line numbers, checked against the schema, defaults filled in."""
from __future__ import annotations

import os

from .validate import validate
from .yaml_lines import CaseError, load_with_lines

__all__ = ["CaseError", "load_case"]


def load_case(path: str) -> dict:
    """Return the validated case; the case name is the file's stem (cases/<case>/<case>.yaml)."""
    data, lines = load_with_lines(path)
    case = validate(data, path, lines)
    case["_path"] = path
    case["_lines"] = lines
    case["_name"] = os.path.splitext(os.path.basename(path))[0]
    return case
