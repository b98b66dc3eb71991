"""Read a case file: YAML with line numbers, checked against the schema, defaults filled in."""
from __future__ import annotations

import os

from .validate import validate
from .yaml_lines import CaseError, load_with_lines

__all__ = ["CaseError", "load_case"]


def load_case(path: str) -> dict:
    """Return the validated case.

    Its name is the folder's for cases/<case>/<case>.yaml, and "<case>-<config>" for a
    variant cases/<case>/<config>.yaml: the name of its folder under out/ (see Makefile).
    """
    data, lines = load_with_lines(path)
    case = validate(data, path, lines)
    case["_path"] = path
    case["_lines"] = lines
    stem = os.path.splitext(os.path.basename(path))[0]
    folder = os.path.basename(os.path.dirname(os.path.abspath(path)))
    case["_name"] = stem if stem == folder else f"{folder}-{stem}"
    return case
