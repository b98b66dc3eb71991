"""Check a loaded case file against pipeline/schema.py and fill in the defaults.

Every error names the file, the line and the key, and says what to do:
    plate.yaml:14: time.safety_factr: unknown key (did you mean 'safety_factor'?)
All errors of a file are collected and reported together, before any work is done.
"""
from __future__ import annotations

import copy
import difflib
import math
import re

from .schema import CASE, MODEL_KEYS, MODEL_NOTE, MODEL_REQUIRED, REQUIRED, Key
from .yaml_lines import MAX_NUMBER, CaseError, dotted

MAX_INTEGER = 2 ** 53
MAX_TEXT = 200  # characters in a text value (title, set name)
# Lists that multiply postprocess's work (issue 36, item 12: 90 000 figures.times passed check and
# drew PNGs for minutes): each figures.times entry is a damage and a displacement map; each frame is
# read by postprocess (history plots, crack tip, output.gmsh: all) and written by the solver.
MAX_FIGURE_TIMES = 24
MAX_FRAMES = 10_000
NAME_PATTERN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
COMPONENTS = ("x", "y", "z")


def yaml11_hint(value) -> str:
    """A hint for the YAML 1.1 number forms that YAML 1.2 (pipeline/yaml_lines.py) reads as text."""
    if isinstance(value, str) and re.fullmatch(r"[-+]?(0b[01_]+|[0-9][0-9_]*(\.[0-9_]*)?([eE][-+]?[0-9]+)?)",
                                               value):
        return " (YAML 1.2 reads this as text: write the number without '_' or 0b, e.g. 1000)"
    if isinstance(value, str) and value.lower() in ("yes", "no", "on", "off", "y", "n"):
        return " (YAML 1.2 reads this as text; write true or false where a switch is meant)"
    return ""


class _Checker:
    def __init__(self, path: str, lines: dict):
        self.path = path
        self.lines = lines
        self.errors: list[str] = []

    def line_of(self, keypath: tuple) -> int:
        # The nearest enclosing key that has a line: a missing key reports its parent's line.
        while keypath and keypath not in self.lines:
            keypath = keypath[:-1]
        return self.lines.get(keypath, 1)

    def error(self, keypath: tuple, message: str):
        self.errors.append(f"{self.path}:{self.line_of(keypath)}: {dotted(keypath) or '<top>'}: {message}")

    # -- scalar kinds -------------------------------------------------------
    def number(self, value, keypath: tuple, key: Key):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.error(keypath, f"expected a number{self.unit(key)}, got {value!r}{yaml11_hint(value)}")
            return None
        if isinstance(value, int) and abs(value) > MAX_NUMBER:  # float() would raise OverflowError
            # (its size from bit_length: str() of a 5000-digit int raises ValueError in Python ≥ 3.11)
            self.error(keypath, f"a whole number of about 10^{int(value.bit_length() * 0.30103)} is too large: "
                       f"a number is at most {MAX_NUMBER:.4g}")
            return None
        value = float(value)
        if not math.isfinite(value):
            self.error(keypath, f"expected a finite number, got {value!r}")
            return None
        return self.bounds(value, keypath, key)

    def integer(self, value, keypath: tuple, key: Key):
        # Whole numbers up to 2^53, the range where a double (1e30 in YAML is one) is an exact
        # integer and the solver's int64 holds it: `max_steps: 1e30` passed here before and was
        # refused by the solver naming case.json (issue 17, item 10).
        if isinstance(value, (int, float)) and not isinstance(value, bool) and abs(value) > MAX_INTEGER:
            self.error(keypath, f"{value!r} is too large: a whole number is at most 2^53 = {MAX_INTEGER}")
            return None
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        if isinstance(value, bool) or not isinstance(value, int):
            self.error(keypath, f"expected a whole number, got {value!r}")
            return None
        return self.bounds(value, keypath, key)

    def bounds(self, value, keypath, key: Key):
        if key.above is not None and not value > key.above:
            self.error(keypath, f"must be greater than {key.above:g}{self.unit(key)}, got {value:g}")
            return None
        if key.minimum is not None and value < key.minimum:
            self.error(keypath, f"must be at least {key.minimum:g}{self.unit(key)}, got {value:g}")
            return None
        if key.below is not None and not value < key.below:
            self.error(keypath, f"must be less than {key.below:g}{self.unit(key)}, got {value:g}")
            return None
        if key.maximum is not None and value > key.maximum:
            self.error(keypath, f"must be at most {key.maximum:g}{self.unit(key)}, got {value:g}")
            return None
        return value

    @staticmethod
    def unit(key: Key) -> str:
        return f" [{key.unit}]" if key.unit else ""

    def choice(self, value, keypath: tuple, key: Key):
        # The choice itself, of its own type: `dimension: 2.0` equals 2 in Python but reached gmsh
        # as "-2.0" (issue 17, item 10).
        for option in key.choices:
            if value == option and type(value) is type(option):
                return option
        options = ", ".join(repr(c) for c in key.choices)
        same_text = [c for c in key.choices if str(c) == str(value) or (not isinstance(value, (str, bool)) and c == value)]
        if same_text:
            option = same_text[0]
            how = "without quotes" if isinstance(value, str) else "as a whole number"
            self.error(keypath, f"{value!r} is not one of {options}: write {option!r} {how}")
        else:
            self.error(keypath, f"{value!r} is not one of {options}{self.closest(str(value), [str(c) for c in key.choices])}")
        return None

    @staticmethod
    def closest(word: str, candidates) -> str:
        match = difflib.get_close_matches(word, list(candidates), n=1, cutoff=0.5)
        return f" (did you mean '{match[0]}'?)" if match else ""

    # -- composite kinds ----------------------------------------------------
    def check(self, value, keypath: tuple, key: Key):
        kind = key.kind
        if kind == "number":
            return self.number(value, keypath, key)
        if kind == "integer":
            return self.integer(value, keypath, key)
        if kind == "string" and key.choices:  # a text of a closed set is a choice (issue 36, item 14)
            return self.choice(value, keypath, key)
        if kind == "string":
            if not isinstance(value, str) or not value:
                self.error(keypath, f"expected a non-empty text, got {value!r}")
                return None
            # A name or a one-line title: it is drawn in every figure and written into case.json,
            # run.log and the VTK files, so it is one line of at most MAX_TEXT characters.
            if len(value) > MAX_TEXT or "\n" in value or "\r" in value:
                self.error(keypath, f"expected one line of at most {MAX_TEXT} characters, got "
                           f"{len(value)} characters{' on several lines' if chr(10) in value else ''}; "
                           "shorten it")
                return None
            return value
        if kind == "choice":
            return self.choice(value, keypath, key)
        if kind == "boolean":
            if not isinstance(value, bool):
                self.error(keypath, f"expected true or false, got {value!r}{yaml11_hint(value)}")
                return None
            return value
        if kind == "number_or_choice":
            if isinstance(value, str):
                return self.choice(value, keypath, key)
            return self.number(value, keypath, key)
        if kind == "section":
            return self.mapping(value, keypath, key.fields)
        if kind == "named":
            return self.named(value, keypath, key)
        if kind == "list":
            if not isinstance(value, list):
                self.error(keypath, "expected a list of entries ('- set: ...')")
                return []
            return [self.mapping(item, keypath + (i,), key.fields) for i, item in enumerate(value)]
        if kind == "names":
            what = "names" if key.choices else "node-set names"
            if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
                self.error(keypath, f"expected a list of {what}, got {value!r}")
                return []
            for i, name in enumerate(value):  # a closed list of names (output.fields): each one of them
                if key.choices and name not in key.choices:
                    self.error(keypath + (i,), f"unknown name {name!r}{self.closest(name, key.choices)}; "
                               f"valid: {', '.join(key.choices)}")
            return list(value)
        if kind == "numbers":
            if not isinstance(value, list):
                self.error(keypath, f"expected a list of numbers{self.unit(key)}, got {value!r}")
                return None
            out = [self.number(v, keypath + (i,), Key("number", "", unit=key.unit))
                   for i, v in enumerate(value)]
            return None if None in out else out
        if kind == "parameters":
            if not isinstance(value, dict):
                self.error(keypath, "expected NAME: number entries")
                return {}
            out = {}
            for name, v in value.items():
                if not NAME_PATTERN.match(name):
                    self.error(keypath + (name,), "a gmsh parameter name is letters, digits and '_'")
                out[name] = self.number(v, keypath + (name,), Key("number", ""))
            return out
        if kind == "components":
            return self.components(value, keypath, key)
        if kind == "point_or_name":
            if isinstance(value, str) and NAME_PATTERN.match(value):
                return value
            if isinstance(value, list) and len(value) in (2, 3):
                out = [self.number(v, keypath + (i,), Key("number", "", unit=key.unit)) for i, v in enumerate(value)]
                return None if None in out else out
            self.error(keypath, f"expected a point [x, y] or [x, y, z]{self.unit(key)} or a node-set name, got {value!r}")
            return None
        raise AssertionError(f"schema kind {kind!r} has no checker")

    def mapping(self, value, keypath: tuple, fields: dict):
        if value is None:
            value = {}
        if not isinstance(value, dict):
            self.error(keypath, f"expected a section of keys ({', '.join(fields)}), got {value!r}")
            return {}
        out = {}
        for name, item in value.items():
            if name not in fields:
                self.error(keypath + (name,), f"unknown key{self.closest(name, fields)}; "
                           f"known keys here: {', '.join(fields)}")
        for name, key in fields.items():
            if name in value and value[name] is not None:
                out[name] = self.check(value[name], keypath + (name,), key)
            elif key.required:
                self.error(keypath + (name,), f"missing required key: {key.doc}")
                out[name] = None
            elif key.kind == "section":
                out[name] = self.mapping({}, keypath + (name,), key.fields)
            else:
                out[name] = copy.deepcopy(key.default)
        return out

    def named(self, value, keypath: tuple, key: Key):
        if not isinstance(value, dict) or (key.required and not value):
            self.error(keypath, "expected one or more NAME: entries, NAME a gmsh physical group")
            return {}
        out = {}
        for name, entry in value.items():
            if not NAME_PATTERN.match(name):
                self.error(keypath + (name,), "a name is letters, digits and '_', not starting with a digit")
            out[name] = self.mapping(entry, keypath + (name,), key.fields)
        return out

    def components(self, value, keypath: tuple, key: Key):
        if not isinstance(value, dict) or not value:
            self.error(keypath, "expected components, e.g. {x: 0.0, z: 1.5}")
            return {}
        out = {}
        for comp, v in value.items():
            if comp not in COMPONENTS:
                self.error(keypath + (comp,), f"unknown component{self.closest(str(comp), COMPONENTS)}; "
                           "use x, y or z")
                continue
            out[comp] = self.table(v, keypath + (comp,), key)
        return out

    def table(self, value, keypath: tuple, key: Key):
        """A number, or [[t, v], ...] with t strictly increasing: returned as (times, values)."""
        if isinstance(value, list) and key.table:
            times, values = [], []
            for i, row in enumerate(value):
                if (not isinstance(row, list) or len(row) != 2 or
                        any(isinstance(x, bool) or not isinstance(x, (int, float)) for x in row)):
                    self.error(keypath + (i,), f"a table row is [time, value], got {row!r}")
                    return None
                times.append(float(row[0]))
                values.append(float(row[1]))
            if not times:
                self.error(keypath, "the table is empty; give a number or [[t0, v0], ...]")
                return None
            if any(b <= a for a, b in zip(times, times[1:])):
                self.error(keypath, f"table times must increase strictly, got {times}")
                return None
            return (times, values)
        number = self.number(value, keypath, Key("number", "", unit=key.unit))
        return None if number is None else ([0.0], [number])


def validate(data, path: str, lines: dict) -> dict:
    """Return the case with defaults filled in, or raise CaseError listing every problem."""
    checker = _Checker(path, lines)
    if not isinstance(data, dict):
        raise CaseError(f"{path}:1: the case file must be a mapping of keys (dimension:, materials:, ...)")
    case = checker.mapping(data, (), CASE)
    if checker.errors:
        raise CaseError("\n".join(checker.errors))
    _check_context(case, checker)
    if checker.errors:
        raise CaseError("\n".join(checker.errors))
    return case


def _check_context(case: dict, checker: _Checker):
    """Rules that tie one key to another."""
    dim = case["dimension"]
    if case["analysis"] is None:
        case["analysis"] = "3d" if dim == 3 else "plane_stress"
    probe = case["figures"]["probe"]
    if isinstance(probe, list) and dim == 3 and len(probe) != 3:
        checker.error(("figures", "probe"), f"a point of a 3D case has three coordinates [x, y, z], got {probe!r}")
    if dim == 3 and case["analysis"] != "3d":
        checker.error(("analysis",), f"'{case['analysis']}' is a 2D model but dimension is 3; use 3d")
    if dim == 2 and case["analysis"] == "3d":
        checker.error(("analysis",), "dimension is 2: use plane_stress or plane_strain")
    if dim == 2 and case["thickness"] is None:
        checker.error(("thickness",), "a 2D case needs thickness [m] (node volume = area × thickness)")
    if dim == 3 and case["thickness"] is not None:
        checker.error(("thickness",), "thickness is for 2D cases only; remove it")
    _check_materials(case, checker)
    disc = case["discretization"]
    if disc["method"] == "lattice" and disc["dx"] is None:
        checker.error(("discretization", "dx"), "the lattice method needs dx [m], the node spacing")
    if disc["horizon"] is not None and disc["dx"] is not None and disc["horizon"] < disc["dx"]:
        checker.error(("discretization", "horizon"),
                      f"horizon {disc['horizon']:g} m is smaller than dx {disc['dx']:g} m: nodes would "
                      "have no bonds; use about 3·dx")
    if disc["horizon"] is None and disc["horizon_factor"] < 1.0:
        checker.error(("discretization", "horizon_factor"),
                      "must be at least 1 (the horizon must reach the nearest neighbour); use about 3")
    if disc["origin"] is not None:
        if disc["method"] != "lattice":
            checker.error(("discretization", "origin"), "origin places a lattice; the mesh-nodes method has "
                          "none: remove origin or use method: lattice")
        elif len(disc["origin"]) != dim:
            checker.error(("discretization", "origin"), f"needs {dim} coordinates (dimension {dim}), "
                          f"got {len(disc['origin'])}")
    for name, m in case["materials"].items():
        if m["model"] == "pmb":
            _check_pmb_pairs(name, m, checker)
    if case["breaking_order"] == "lammps" and any(m["model"] != "pmb" for m in case["materials"].values()):
        checker.error(("breaking_order",), "lammps is LAMMPS peri/pmb's order, for model pmb; remove it or "
                      "use model: pmb")
    for i, bc in enumerate(case["boundary_conditions"]):
        kinds = [k for k in ("displacement", "velocity", "body_force") if bc[k]]
        if not kinds:
            checker.error(("boundary_conditions", i), "give displacement, velocity or body_force")
        prescribed = set(bc["displacement"] or {}) & set(bc["velocity"] or {})
        for comp in sorted(prescribed):
            checker.error(("boundary_conditions", i, "velocity", comp),
                          f"component {comp} is given both a displacement and a velocity; keep one")
        if dim == 2:
            pass  # z is allowed in 2D: a membrane moves out of its plane
    for i, ic in enumerate(case["initial_conditions"]):
        if not ic["velocity"] and not ic["displacement"] and not ic["strain"]:
            checker.error(("initial_conditions", i), "give velocity, displacement or strain")
    _check_conflicts(case, checker)
    names = set()
    for i, ind in enumerate(case["indenters"]):
        _check_indenter(ind, i, dim, names, checker)
    for i, crack in enumerate(case["cracks"]):
        _check_crack(crack, i, dim, checker)
    _check_integrator_settings(case, checker)
    out = case["output"]
    if out["every_time"] is not None and out["every_time"] > case["time"]["end"]:
        checker.error(("output", "every_time"), f"{out['every_time']:g} s is longer than the run (time.end = "
                      f"{case['time']['end']:g} s): only the first and the last frame would be written; "
                      "use at most time.end")
    if out["every_time"] is not None and out["every_steps"] is not None:
        checker.error(("output", "every_steps"), "give every_time or every_steps, not both")
    if out["every_time"] is None and out["every_steps"] is None:
        out["every_time"] = case["time"]["end"] / 50.0
    frames = case["time"]["end"] / out["every_time"] if out["every_time"] is not None else 0.0
    if frames > MAX_FRAMES:
        checker.error(("output", "every_time"), f"{out['every_time']:g} s makes {frames:.3g} frames over time.end = "
                      f"{case['time']['end']:g} s; at most {MAX_FRAMES} (each is written, read and drawn from): "
                      f"use every_time ≥ {case['time']['end'] / MAX_FRAMES:.3g} s")
    times = case["figures"]["times"]
    if times is not None and not times:
        checker.error(("figures", "times"), "an empty list; give the times of the maps [s], or leave the key out "
                      "for four frames spread over the run")
    if times is not None and len(times) > MAX_FIGURE_TIMES:
        checker.error(("figures", "times"), f"{len(times)} times; at most {MAX_FIGURE_TIMES}: each draws a damage "
                      "and a displacement map (PNG). Pick the times to show; frames.pvd holds every frame "
                      "(ParaView)")
    for i, name in enumerate(out["fields"]):
        if name in out["fields"][:i]:  # the solver refuses a field listed twice (case_reader.cpp)
            checker.error(("output", "fields", i), f"'{name}' is listed twice; list each field once")


def _check_integrator_settings(case: dict, checker: _Checker):
    """The step limits and solver choices of the integrators' sections, as pdsolve judges them
    (solver/src/io/case_reader.cpp read_adaptive, read_quasi_static, read_implicit and the
    integrators' configure()): before, a case that broke one passed check and was refused by the
    solver, naming case.json instead of the .yaml line (issue 36, item 14)."""
    end = case["time"]["end"]
    integrator = case["time"]["integrator"]
    for name, default_max in (("adaptive", None), ("quasi_static", end / 10.0), ("implicit", end / 10.0)):
        section = case[name]
        dt_min, dt_initial, dt_max = section["dt_min"], section["dt_initial"], section["dt_max"]
        # quasi_static and implicit default dt_max to end/10: a given dt_min above that is refused too
        # (QuasiStatic/Implicit::configure); adaptive's default dt_max comes from eq. 2.5, the mesh's.
        limit = dt_max if dt_max is not None else default_max
        if dt_min is not None and limit is not None and dt_min > limit:
            if dt_max is not None:
                checker.error((name, "dt_min"), f"dt_min {dt_min:g} s is larger than dt_max {dt_max:g} s")
            else:
                checker.error((name, "dt_min"), f"dt_min {dt_min:g} s is larger than the default dt_max "
                              f"{limit:g} s (time.end/10); lower dt_min or give {name}.dt_max")
        if name == "quasi_static":
            continue  # its dt_initial is cut to dt_max by the solver
        if dt_initial is not None and dt_max is not None and dt_initial > dt_max:
            checker.error((name, "dt_initial"), f"dt_initial {dt_initial:g} s is larger than dt_max {dt_max:g} s")
        if dt_initial is not None and dt_min is not None and dt_initial < dt_min:
            checker.error((name, "dt_initial"), f"dt_initial {dt_initial:g} s is smaller than dt_min {dt_min:g} s")
    mixed_start = case["mixed"]["start"] if integrator == "mixed" else None
    # The sections whose settings the run uses: mixed runs quasi_static or implicit steps between its
    # explicit ones, as mixed.start says.
    uses_static = integrator == "quasi_static" or mixed_start == "quasi_static"
    uses_implicit = integrator == "implicit" or mixed_start == "implicit"
    if uses_static and case["damping"] != 0.0:
        # QuasiStatic::configure: equilibrium has no velocity for damping to act on.
        how = "mixed.start: implicit (its steps integrate damping)" if integrator == "mixed" else \
            "time.integrator: verlet or implicit"
        checker.error(("damping",), f"{case['damping']:g} 1/s, but the {integrator} integrator solves load steps "
                      f"for equilibrium, where damping does nothing: set damping: 0, or use {how}")
    # Contact has no assembled tangent (solver/src/operator/force_operator.cpp
    # missing_assembled_stiffness): linear_solver direct is refused when contact is on
    # (integrators/newton_krylov.cpp), as for lps (_check_materials).
    contact = case["contact"]
    contact_on = contact["enabled"] == "on" or (contact["enabled"] == "auto" and
                                                (len(case["materials"]) > 1 or contact["self_contact"]))
    if contact_on:
        why = ("contact.enabled is on" if contact["enabled"] == "on" else
               "contact is on (contact.enabled auto, with " +
               ("self_contact" if contact["self_contact"] else f"{len(case['materials'])} blocks") + ")")
        for name, used in (("quasi_static", uses_static), ("implicit", uses_implicit)):
            if used and case[name]["linear_solver"] == "direct":
                checker.error((name, "linear_solver"), f"direct factorises the assembled tangent stiffness, and {why}, "
                              "which has none; use linear_solver: cg (or auto), or contact.enabled: off")


def _check_pmb_pairs(name: str, m: dict, checker: _Checker):
    """PMB's constants come from one pair: E with G0 (docs/theory.md T2) or c with s0 as given
    (a LAMMPS pair_coeff), never a mix; α only for a material that can break."""
    pairs = "give youngs_modulus (and fracture_energy) or micromodulus (and critical_stretch), not a mix"
    where = ("materials", name)
    e, g0 = m["youngs_modulus"] is not None, m["fracture_energy"] is not None
    c, s0 = m["micromodulus"] is not None, m["critical_stretch"] is not None
    if e and c:
        checker.error(where + ("micromodulus",), f"is given beside youngs_modulus: {pairs}")
    elif not e and not c:
        checker.error(where, f"needs a stiffness: {pairs}")
    elif e and s0:
        checker.error(where + ("critical_stretch",), f"is given with youngs_modulus: {pairs} "
                      "(fracture_energy gives s0 from E)")
    elif c and g0:
        checker.error(where + ("fracture_energy",), f"is given with micromodulus: {pairs} "
                      "(critical_stretch is s0 itself)")
    elif (m["critical_stretch_alpha"] or 0.0) > 0.0 and not g0 and not s0:
        checker.error(where + ("critical_stretch_alpha",), "needs a breakable material: give "
                      "fracture_energy or critical_stretch")


def _check_materials(case: dict, checker: _Checker):
    """Each block gives the keys of its model and no other model's (poisson_ratio under model: pmb is
    an error that says why and which model has it); every block uses one model and one influence
    function (a bond joins two blocks, and m_i sums over both)."""
    materials = case["materials"]
    models = {m["model"] for m in materials.values()}
    for name, m in materials.items():
        model = m["model"]
        for key in sorted({k for keys in MODEL_KEYS.values() for k in keys} - set(MODEL_KEYS[model])):
            if m.get(key) is None:
                continue
            owners = [other for other, keys in MODEL_KEYS.items() if key in keys]
            note = MODEL_NOTE.get(model, f"model {model!r} has no parameter {key!r}")
            checker.error(("materials", name, key), f"{note}; {key} belongs to model {' or '.join(owners)}: "
                          f"set model: {owners[0]} (or remove {key})")
        for key in MODEL_REQUIRED.get(model, ()):
            if m.get(key) is None:
                checker.error(("materials", name, key), f"model {model} needs {key}: {CASE['materials'].fields[key].doc}")
    if len(models) > 1:
        checker.error(("materials",), f"every block must use the same model, got {', '.join(sorted(models))}")
    integrator = case["time"]["integrator"]
    if "lps" in models:
        # A state-based law has no assembled tangent (solver/src/materials/bond_model.hpp
        # bond_tangent_row: its force on a node depends on the neighbours' neighbours). Its Newton
        # solves run matrix-free: CG with the law's diagonal blocks (quasi_static, implicit, mixed);
        # linear_solver: direct, which factorises the tangent, is refused, as the solver does.
        starts_implicit = integrator == "mixed" and case["mixed"].get("start") == "implicit"
        if (integrator == "implicit" or starts_implicit) and case["implicit"].get("linear_solver") == "direct":
            checker.error(("implicit", "linear_solver"), "direct factorises the assembled tangent stiffness, which "
                          "the state-based model lps does not have; use linear_solver: cg (or auto)")
        elif integrator in ("quasi_static", "mixed") and case["quasi_static"].get("linear_solver") == "direct":
            checker.error(("quasi_static", "linear_solver"), "direct factorises the assembled tangent stiffness, which "
                          "the state-based model lps does not have; use linear_solver: cg (or auto)")
        elif integrator in ("quasi_static", "mixed") and case["quasi_static"].get("preconditioner") == "amg":
            checker.error(("quasi_static", "preconditioner"), "amg is set up on the assembled tangent stiffness, which "
                          "the state-based model lps does not have; use preconditioner: block_jacobi (or auto)")
    influences = {m.get("influence") or "one" for m in materials.values() if m["model"] == "lps"}
    if len(influences) > 1:
        checker.error(("materials",), f"every block must use the same influence function, got {', '.join(sorted(influences))}")


def _check_conflicts(case: dict, checker: _Checker):
    """Two conditions on one set and component, where the solver would silently apply the last
    (issue 17, item 10: a clamped edge moved 1 mm). Overlaps of different sets are checked once
    the node sets exist (pipeline/stability.py, check_discretized_case)."""
    prescribed: dict[tuple, tuple] = {}   # (set, component) → (index, kind) of the first condition
    for i, bc in enumerate(case["boundary_conditions"]):
        for kind in ("displacement", "velocity"):
            for comp in sorted(bc[kind] or {}):
                first = prescribed.setdefault((bc["set"], comp), (i, kind))
                if first[0] != i:
                    where = ("boundary_conditions", first[0], first[1], comp)
                    checker.error(("boundary_conditions", i, kind, comp),
                                  f"set '{bc['set']}' component {comp} is already given a {first[1]} by "
                                  f"boundary_conditions[{first[0]}] (line {checker.line_of(where)}); only one "
                                  "would act: keep one")
    initial: dict[tuple, int] = {}
    for i, ic in enumerate(case["initial_conditions"]):
        for kind in ("velocity", "displacement"):
            for comp in sorted(ic[kind] or {}):
                first = initial.setdefault((ic["set"], kind, comp), i)
                if first != i:
                    where = ("initial_conditions", first, kind, comp)
                    checker.error(("initial_conditions", i, kind, comp),
                                  f"set '{ic['set']}' is given an initial {kind} {comp} twice (also "
                                  f"initial_conditions[{first}], line {checker.line_of(where)}); keep one")
                if kind == "velocity" and (ic["set"], comp) in prescribed:
                    j, bc_kind = prescribed[(ic["set"], comp)]
                    checker.error(("initial_conditions", i, kind, comp),
                                  f"set '{ic['set']}' component {comp} has a prescribed {bc_kind} "
                                  f"(boundary_conditions[{j}], line "
                                  f"{checker.line_of(('boundary_conditions', j, bc_kind, comp))}): the initial "
                                  "velocity would be ignored there; remove one")


def _check_crack(crack: dict, i: int, dim: int, checker: _Checker):
    """A pre-crack is two distinct points of the case's dimension (z = 0 is filled in for 2D)."""
    for key in ("from", "to"):
        point = crack[key]
        if point is not None and len(point) not in ((2, 3) if dim == 2 else (3,)):
            checker.error(("cracks", i, key), f"expected {'2 or 3' if dim == 2 else '3'} components, got {len(point)}")
            return
    if crack["from"] is not None and crack["to"] is not None and crack["from"][:2] == crack["to"][:2]:
        checker.error(("cracks", i), "from and to are the same point in the xy plane")


def _check_indenter(ind: dict, i: int, dim: int, names: set, checker: _Checker):
    """An indenter's vectors have the case's dimension, its shape has what it needs, names are unique."""
    where = ("indenters", i)
    name = ind["name"]
    if name is not None:
        if not NAME_PATTERN.match(name):
            checker.error(where + ("name",), "letters, digits and '_', not starting with a digit "
                          "(it names history.csv columns)")
        if name in names:
            checker.error(where + ("name",), f"'{name}' is used twice; give each indenter its own name")
        names.add(name)
    for key in ("centre", "velocity", "normal", "axis"):
        vector = ind[key]
        if vector is None:
            continue
        if len(vector) not in ((2, 3) if dim == 2 else (3,)):
            checker.error(where + (key,), f"expected {'2 or 3' if dim == 2 else '3'} components, got {len(vector)}")
            continue
        ind[key] = [float(c) for c in vector] + [0.0] * (3 - len(vector))
        if key in ("normal", "axis"):
            # The solver divides by the length √(x² + y² + z²) in doubles (case_reader.cpp
            # read_direction): components like 1e200 overflow it and 1e-200 underflow it to 0.
            length = math.sqrt(sum(c * c for c in ind[key]))
            if not any(ind[key]):
                checker.error(where + (key,), "must be a non-zero direction")
            elif not (0.0 < length < math.inf):
                checker.error(where + (key,), f"its length {'overflows' if length else 'underflows'} a double; "
                              "give the direction with components of about 1, e.g. [0, 1, 0]")
    shape = ind["shape"]
    if shape in ("sphere", "cylinder") and ind["radius"] is None:
        checker.error(where + ("radius",), f"a {shape} indenter needs radius [m]")
    if shape == "plane" and ind["normal"] is None:
        checker.error(where + ("normal",), "a plane indenter needs normal, pointing towards the body it pushes")
