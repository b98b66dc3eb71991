"""A case file held in memory: read, changed by dotted keys, written and run stage by stage."""
from __future__ import annotations

import copy
import glob
import os

import yaml

from common.atomic import write_atomically
from pipeline.case import CaseError, load_case
from common.output_lock import FolderInUse, output_lock
from common.paths import REPOSITORY, pdsolve
from pipeline.yaml_lines import load_with_lines


class RunError(RuntimeError):
    """A stage failed: the message names the stage, the command or file, and the log to read."""


def load(path: str) -> "Case":
    """The case file at `path` (checked against the schema now, so a bad file fails here)."""
    load_case(path)  # CaseError with the file, the line and the key
    # The data as the checker read it (YAML 1.2, pipeline/yaml_lines.py), not yaml.safe_load's
    # YAML 1.1 reading of the same text; and the file is read once more only through the bounded
    # loader (a regular file of at most 1 MiB).
    data, _lines = load_with_lines(path)
    return Case(data or {}, source=path)


def _parts(key: str) -> list:
    """"materials.glass.density" → ["materials", "glass", "density"]; "boundary_conditions.0.set"
    → [..., 0, ...] (a list index)."""
    return [int(p) if p.isdigit() else p for p in key.split(".")]


def _what(value) -> str:
    """How a value that is not a section reads in an error: 'a number (0.001)', 'a list of 2 entries'."""
    if isinstance(value, list):
        return f"a list of {len(value)} entries"
    if isinstance(value, bool) or value is None:
        return repr(value)
    kind = "a number" if isinstance(value, (int, float)) else "a text" if isinstance(value, str) else type(value).__name__
    return f"{kind} ({value!r})"


def _step(node, part, walked: str, key: str):
    """node[part] for Case.__getitem__/__setitem__, or a KeyError naming the path walked so far:
    an index past the end of a list, a name given to a list, a key under a number (before, an
    IndexError or a TypeError from deep inside, issue 36 item 13)."""
    where = walked or "the case file"
    if isinstance(node, list):
        if not isinstance(part, int):
            raise KeyError(f"{key}: {where} is a list of {len(node)} entries: give an index, e.g. {walked}.0")
        if part >= len(node):
            has = f"has {len(node)} entries (indices 0 to {len(node) - 1})" if node else "is an empty list"
            raise KeyError(f"{key}: {where} {has}, no index {part}; set the whole list to add entries")
        return node[part]
    if isinstance(node, dict):
        return node[str(part)]  # KeyError: the caller says what is missing
    raise KeyError(f"{key}: {where} is {_what(node)}, not a section: it has no key '{part}'")


def _plain(value, key: str):
    """The value as YAML can write it: numpy scalars and arrays become Python numbers and lists
    (PyYAML's safe dumper raised RepresenterError on them, leaving a half-written case file), tuples
    lists; anything else that is no number, text, list or mapping is refused, naming the key."""
    if value is None or type(value) in (bool, int, float, str):
        return value
    try:
        import numpy as np
    except ImportError:  # peridyn runs without numpy too
        np = None
    if np is not None and isinstance(value, (np.generic, np.ndarray)):
        plain = value.tolist()  # Python scalars, nested lists for arrays
        if isinstance(plain, np.generic):  # longdouble and its kin stay numpy: a double is what YAML holds
            if isinstance(plain, (np.floating, np.integer)):
                return float(plain) if isinstance(plain, np.floating) else int(plain)
            raise TypeError(f"{key}: a numpy {type(plain).__name__} cannot be written to a case file; give a number")
        return _plain(plain, key)
    for plain in (bool, int, float, str):  # a subclass (an IntEnum, a str subclass): its plain value
        if isinstance(value, plain):
            return plain(value)
    if isinstance(value, (list, tuple)):
        return [_plain(item, f"{key}.{i}") for i, item in enumerate(value)]
    if isinstance(value, dict):
        return {str(name): _plain(item, f"{key}.{name}") for name, item in value.items()}
    raise TypeError(f"{key}: a {type(value).__module__}.{type(value).__qualname__} cannot be written to a case "
                    "file; give a number, a text, true/false, a list or a mapping of them")


class Case:
    """The case file's data (a nested dict as YAML reads it) and the folder it came from, where the
    case's .geo or given mesh (cases/<case>/<case>.geo | .unv | .msh) is found."""

    def __init__(self, data: dict, source: str):
        self.data = copy.deepcopy(data)
        self.source = os.path.abspath(source)

    @property
    def folder(self) -> str:
        return os.path.dirname(self.source)

    @property
    def base_name(self) -> str:
        """The case's folder name: its .geo or mesh is <folder>/<base_name>.geo | .unv | .msh."""
        return os.path.basename(self.folder)

    def __getitem__(self, key: str):
        node, walked = self.data, ""
        for part in _parts(key):
            try:
                node = _step(node, part, walked, key)
            except KeyError as err:
                if isinstance(node, dict):  # a name missing from a section
                    raise KeyError(f"{key}: not in the case file {self.source} (defaults are in "
                                   "docs/case-file.md)") from None
                raise KeyError(err.args[0]) from None
            walked = f"{walked}.{part}" if walked else str(part)
        return node

    def __setitem__(self, key: str, value):
        """Set a dotted key, making the sections on the way; checked against the schema at run().

        numpy scalars and arrays are stored as Python numbers and lists; an index past the end of
        a list, or a key under a value that is not a section, is a KeyError naming the path."""
        value = _plain(value, key)
        parts = _parts(key)
        node, walked = self.data, ""
        for part in parts[:-1]:
            if isinstance(node, dict) and str(part) not in node:
                node[str(part)] = {}
            node = _step(node, part, walked, key)
            walked = f"{walked}.{part}" if walked else str(part)
        last = parts[-1]
        if isinstance(node, list):
            _step(node, last, walked, key)  # the index must exist
            node[last] = value
        elif isinstance(node, dict):
            node[str(last)] = value
        else:
            _step(node, last, walked, key)  # raises: a key under a number

    def copy(self) -> "Case":
        return Case(self.data, self.source)

    def write(self, path: str) -> str:
        """Write the case file (YAML) and check it; returns the path.

        The YAML is made in memory first (values put into self.data directly, not through
        case[key] = value, are made plain here too) and written under a temporary name and renamed
        (common/atomic.py): a value YAML cannot hold leaves no file, half-written or not."""
        plain = {str(name): _plain(value, str(name)) for name, value in self.data.items()}
        text = yaml.safe_dump(plain, sort_keys=False, allow_unicode=True)
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        write_atomically(path, text)
        load_case(path)
        return path

    def mesh_source(self) -> tuple[str, str]:
        """("given", path) of cases/<case>/<case>.unv|.msh, else ("geo", path of the .geo). Each of the
        folder's inputs must be a regular file inside it, as make's stages require (pipeline/inputs.py):
        a .unv linked to /etc/shadow had its first line printed through Case.run (issue 36 probe)."""
        from pipeline.inputs import CASE_FILE_EXTENSIONS
        from preprocess.errors import PreprocessError
        from preprocess.geo_guard import check_inside

        for ext in CASE_FILE_EXTENSIONS:
            path = os.path.join(self.folder, self.base_name + ext)
            if os.path.lexists(path):
                try:
                    check_inside(path, self.folder)
                except PreprocessError as error:
                    raise RunError(str(error)) from None
        for ext in (".unv", ".msh"):
            path = os.path.join(self.folder, self.base_name + ext)
            if os.path.isfile(path):
                return "given", path
        geo = os.path.join(self.folder, self.base_name + ".geo")
        if not os.path.isfile(geo):
            raise RunError(f"{self.source}: no mesh {self.base_name}.unv/.msh and no {self.base_name}.geo "
                           f"in {self.folder}: a case needs one of them")
        return "geo", geo

    def run(self, out_dir: str, *, figures: bool = True, threads: int | None = None,
            solver: str | None = None, log=None):
        """Run the case into `out_dir` through make's stages; returns a results.Run.

        The case file is written to <out_dir>/<basename(out_dir)>.yaml, so the run's name (in
        case.json and the figures) is the folder's. The mesh is made again only when the gmsh
        parameters changed (as make does); the solver's output goes to <out_dir>/solver.log.
        solver: pdsolve's path (default: PDSOLVE, else build/solver/pdsolve); threads: its --threads.
        """
        say = log or (lambda text: None)
        out_dir = os.path.abspath(out_dir)
        # The lock make takes too (common/output_lock.py): two runs into one folder, or a run beside
        # `make case=X` into out/X/, wrote each other's files (issue 36, item 5).
        try:
            with output_lock(out_dir, f"peridyn Case.run of {self.source}") as lock_fd:
                return self._run_locked(out_dir, lock_fd, figures, threads, solver, say)
        except FolderInUse as error:
            raise RunError(str(error)) from None

    def _run_locked(self, out_dir, lock_fd, figures, threads, solver, say):
        """run()'s stages, with out_dir locked by lock_fd (handed to the solver: the folder stays
        locked while it runs, even if this process is killed)."""
        from pipeline import stages
        from pipeline.solver_physics import SolverError

        from .results import Run

        name = os.path.basename(out_dir)
        yaml_path = self.write(os.path.join(out_dir, name + ".yaml"))
        kind, mesh = self.mesh_source()
        if kind == "geo":
            params, target = os.path.join(out_dir, "mesh-parameters.json"), os.path.join(out_dir, "mesh.msh")
            before = os.path.getmtime(params) if os.path.isfile(params) else None
            stages.mesh_parameters(yaml_path, params)
            if not os.path.isfile(target) or os.path.getmtime(params) != before:
                say(f"mesh: {mesh} → {target}")
                stages.mesh(yaml_path, mesh, target)
            mesh = target
        # Before preprocess, which asks this solver for the stable step (pipeline/solver_physics.py).
        solver = solver or pdsolve()
        if not os.path.isfile(solver):
            raise RunError(f"{solver}: the solver is not built; run `make solver` in {REPOSITORY}")
        say(f"preprocess: {yaml_path} + {mesh} → {out_dir}/nodes.vtu, case.json")
        try:
            stages.preprocess(yaml_path, mesh, out_dir, solver=solver)
        except SolverError as error:
            raise RunError(str(error)) from None
        for stale in glob.glob(os.path.join(out_dir, "frames", "*.vtu")):
            os.unlink(stale)  # frames of an earlier, longer run would stay listed nowhere but on disk
        case_json = os.path.join(out_dir, "case.json")
        say("solve: " + " ".join(stages.solve_command(case_json, solver=solver, threads=threads)))
        # The lock's descriptor goes to pdsolve, which locks its folder itself and finds it held for it.
        result = stages.solve(case_json, solver=solver, threads=threads, log=os.path.join(out_dir, "solver.log"),
                              lock_fd=lock_fd)
        if result.returncode != 0:
            raise RunError(f"{' '.join(result.args)} failed (exit {result.returncode}); see {out_dir}/solver.log "
                           "and run.log")
        if figures:
            say(f"postprocess: {out_dir}")
            stages.postprocess(out_dir, log=say)
        return Run(out_dir)

    def __repr__(self) -> str:
        return f"peridyn.Case({self.source!r})"


__all__ = ["Case", "CaseError", "RunError", "load"]
