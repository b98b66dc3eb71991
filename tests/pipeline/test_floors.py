"""The Python side's floors (docs/architecture.md, issue 37 item 6): each package imports only the
ones below it, and no file edits sys.path. Before, preprocess and postprocess imported
pipeline/atomic.py while pipeline imported preprocess, and 26 files inserted into sys.path."""
import ast
import os

from common.paths import REPOSITORY

# Each package and the packages of ours it may import (besides itself).
BELOW = {
    "common": set(),
    "preprocess": {"common"},
    "postprocess": {"common"},
    "pipeline": {"common", "preprocess", "postprocess"},
    "peridyn": {"common", "preprocess", "postprocess", "pipeline"},
    "validation": {"common", "preprocess", "postprocess", "pipeline"},
    "bench": {"common", "preprocess", "postprocess", "pipeline"},
}


def python_files(*folders):
    for folder in folders:
        for parent, _dirs, names in os.walk(os.path.join(REPOSITORY, folder)):
            yield from (os.path.join(parent, n) for n in sorted(names) if n.endswith(".py"))


def imported_packages(path: str) -> set:
    """The top-level names of every absolute import in the file, those inside functions too."""
    tree = ast.parse(open(path, encoding="utf-8").read(), path)
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return names


def test_every_package_imports_only_the_floors_below_it():
    upward = []
    for package, allowed in BELOW.items():
        for path in python_files(package):
            for name in (imported_packages(path) & set(BELOW)) - allowed - {package}:
                upward.append(f"{os.path.relpath(path, REPOSITORY)} imports {name}")
    assert upward == []


def test_no_file_edits_sys_path():
    edits = []
    for path in python_files(*BELOW, "tests", "docs"):
        tree = ast.parse(open(path, encoding="utf-8").read(), path)
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and node.attr in ("insert", "append", "extend")
                    and isinstance(node.value, ast.Attribute) and node.value.attr == "path"
                    and isinstance(node.value.value, ast.Name) and node.value.value.id == "sys"):
                edits.append(f"{os.path.relpath(path, REPOSITORY)}:{node.lineno}")
    assert edits == []
