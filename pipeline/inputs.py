"""Every input of a case is a regular file inside its case folder, before any stage reads one.

Cases are shared: `ln -s /etc/shadow cases/leak/leak.geo; make case=leak` had gmsh print the
file's first line in its syntax error. The case folder is the .yaml's folder; its inputs are the
.yaml, the folder's <name>.geo (with the <name>.geo.opt gmsh merges by itself), <name>.unv and
<name>.msh (the names the Makefile uses), and any .geo or mesh a stage is given that lies in the
folder. Each must resolve (symbolic links followed) to a regular file inside the folder: a link
that stays inside is fine. Files the .geo Includes are checked by preprocess/geo_guard.py.
A mesh outside the case folder is the pipeline's own (out/<case>/mesh.msh) and is not checked.
"""
from __future__ import annotations

import os

from preprocess.geo_guard import check_inside

CASE_FILE_EXTENSIONS = (".geo", ".geo.opt", ".unv", ".msh")


def case_folder(yaml_path: str) -> str:
    return os.path.realpath(os.path.dirname(os.path.abspath(yaml_path)))


def check_case_inputs(yaml_path: str, *given: str | None):
    """PreprocessError naming the first input that is a link out of the case folder, a folder, a
    device or a FIFO; `given` are the .geo or mesh paths a stage was called with (None: none)."""
    folder = os.path.dirname(os.path.abspath(yaml_path))
    real_folder = case_folder(yaml_path)
    check_inside(yaml_path, real_folder)
    name = os.path.basename(folder)
    for ext in CASE_FILE_EXTENSIONS:
        path = os.path.join(folder, name + ext)
        if os.path.lexists(path):   # a dangling link too: gmsh or make would follow it later
            check_inside(path, real_folder)
    for path in given:
        if path is None:
            continue
        parent = os.path.realpath(os.path.dirname(os.path.abspath(path)))
        if parent == real_folder:
            check_inside(path, real_folder)
