"""pipeline/schema.py against `pdsolve --describe`: the keys that go to case.json, with the same
defaults, choices and ranges on both sides, so the two halves of the schema cannot drift.

Which keys go to case.json is decided by pipeline/resolve.py; the set compared is the set of key
paths of a case.json it writes for a case that uses every key (every indenter shape, every kind of
condition). Names and units differ between the YAML and case.json in a few places; RENAMED,
MADE_BY_RESOLVE and DERIVED below state how.
"""
import json
import subprocess
import textwrap

import pytest

from pipeline import schema
from pipeline.case import load_case
from pipeline.resolve import resolve

# case.json path → schema path, where the names differ.
RENAMED = {
    "partial_volume": "discretization.partial_volume",
    "surface_correction": "discretization.surface_correction",
    "no_fail_sets": "no_fail",
    "blocks": "materials",
    "initial_conditions[].gradient": "initial_conditions[].strain",  # strain_x·x becomes gradient
}
# case.json keys that no schema key holds: resolve.py makes them (names, numbering, the mesh's
# spacing, δ from horizon / horizon_factor × dx, conditions split per component).
MADE_BY_RESOLVE = {
    "format_version", "case", "source", "nodes_file", "output_dir", "grid_spacing", "horizon", "node_sets",
    "blocks[].id", "blocks[].name",
    "boundary_conditions[].kind", "boundary_conditions[].component", "boundary_conditions[].times",
    "boundary_conditions[].values",
    "initial_conditions[].kind", "initial_conditions[].component", "initial_conditions[].value",
}
# Defaults that one side derives: (schema default, solver default, who fills it in).
DERIVED = {
    "analysis": (None, "required", "validate.py: 3d in 3D, plane_stress in 2D"),
    "thickness": (None, 0.0, "required in 2D by both; unused in 3D"),
    "contact.skin": (None, 0.0, "resolve.py writes dx/2; the solver's 0 means dx/2 as well"),
    "indenters[].radius": (None, 0.0, "required for sphere and cylinder by both"),
    "indenters[].normal": (None, [0.0, 0.0, 0.0], "required for a plane by both"),
    "indenters[].velocity": (None, [0.0, 0.0, 0.0], "resolve.py writes [0, 0, 0]"),
    "indenters[].axis": (None, [0.0, 0.0, 1.0], "resolve.py writes z, as the solver's default"),
    "initial_conditions[].gradient": (None, 0.0, "strain absent: no gradient"),
}
KIND_TO_TYPE = {"number": "number", "integer": "integer", "string": "string", "boolean": "boolean",
                "names": "strings", "numbers": "numbers", "number_or_choice": "number_or_choice",
                "section": "object", "named": "list", "list": "list", "components": "number"}

EVERYTHING = """\
title: every key
dimension: 2
analysis: plane_stress
thickness: 0.001
discretization:
  dx: 0.001
  partial_volume: lammps
  surface_correction: energy
materials:
  plate: {density: 2000, youngs_modulus: 1.0e9, fracture_energy: 10}
  disk: {density: 7800, youngs_modulus: 2.0e11}
  rod: {density: 2440, micromodulus: 3.4e21, critical_stretch: 0.001, critical_stretch_alpha: 0.25}
breaking_order: lammps
no_fail: [left]
boundary_conditions:
  - {set: left, displacement: {x: 0}, velocity: {y: [[0, 0], [1, 1]]}, body_force: {z: 1}}
initial_conditions:
  - {set: left, velocity: {z: 1}, displacement: {y: 0}, strain: {x: 0.001}}
cracks:
  - {from: [0, 0], to: [1, 0]}
damping: 1
contact: {enabled: "on", self_contact: true, stiffness_factor: 10}
indenters:
  - {name: ball, shape: sphere, radius: 0.01, centre: [0, 0, 0], velocity: [0, 1, 0], stiffness: 1.0e12}
  - {name: roll, shape: cylinder, radius: 0.01, centre: [0, 0, 0], axis: [0, 0, 1], stiffness: 1.0e12}
  - {name: wall, shape: plane, centre: [0, 0, 0], normal: [1, 0, 0], stiffness: 1.0e12}
time: {end: 1.0e-3, integrator: adaptive, dt: exact, safety_factor: 0.5, max_steps: 10}
adaptive: {tol: 0.01, kd: 10, p: 2, phi: 0.5, dt_initial: 1.0e-8, dt_min: 1.0e-9, dt_max: 1.0e-7}
output: {every_steps: 10, history_every: 2, reactions: [left], restart_every_time: 1.0e-4,
         restart_every_steps: 100}
"""


@pytest.fixture(scope="module")
def described(pdsolve):
    out = subprocess.run([pdsolve, "--describe"], check=True, capture_output=True, text=True).stdout
    return json.loads(out)


# The keys of the other material model: every block of a case uses one model, so the state-based
# LPS keys come from a second case (EVERYTHING with its materials replaced).
EVERYTHING_LPS = EVERYTHING.replace("breaking_order: lammps\n", "").replace(
    "  plate: {density: 2000, youngs_modulus: 1.0e9, fracture_energy: 10}\n"
    "  disk: {density: 7800, youngs_modulus: 2.0e11}\n"
    "  rod: {density: 2440, micromodulus: 3.4e21, critical_stretch: 0.001, critical_stretch_alpha: 0.25}\n",
    "  plate: {model: lps, density: 2000, youngs_modulus: 1.0e9, poisson_ratio: 0.3, fracture_energy: 10,\n"
    "          influence: gaussian}\n"
    "  disk: {model: lps, density: 7800, youngs_modulus: 2.0e11, poisson_ratio: 0.29, influence: gaussian}\n")


@pytest.fixture(scope="module")
def case_json_paths(tmp_path_factory):
    assert EVERYTHING_LPS != EVERYTHING
    resolved_cases = []
    for name, text in (("every.yaml", EVERYTHING), ("every_lps.yaml", EVERYTHING_LPS)):
        path = tmp_path_factory.mktemp("describe") / name
        path.write_text(textwrap.dedent(text))
        resolved_cases.append(resolve(load_case(str(path)), node_sets=["left"], grid_spacing=0.001,
                                      nodes_file="nodes.vtu"))
    paths = set()

    def walk(value, prefix):
        if isinstance(value, dict):
            for name, v in value.items():
                paths.add(prefix + name)
                if prefix + name != "figures":  # postprocess only: the solver checks it is an object
                    walk(v, prefix + name + ".")
        elif isinstance(value, list) and value and isinstance(value[0], dict):
            for item in value:
                walk(item, prefix[:-1] + "[].")

    for resolved in resolved_cases:
        walk(resolved, "")
    return paths


def schema_key(path: str) -> schema.Key:
    """The schema's Key for a case.json path, through RENAMED."""
    path = RENAMED.get(path, path)
    if path.startswith("blocks[]."):
        return schema.MATERIAL[path.split(".", 1)[1]]
    keys, key = schema.CASE, None
    for part in path.split("."):
        key = keys[part.removesuffix("[]")]
        keys = key.fields
    return key


def test_the_solver_reads_exactly_the_keys_resolve_writes(described, case_json_paths):
    solver = set(described["keys"])
    assert sorted(case_json_paths - solver) == []  # written, but the solver would reject it
    assert sorted(solver - case_json_paths) == []  # read, but never written


def test_every_key_that_reaches_the_solver_agrees_with_the_schema(described, case_json_paths):
    problems = []
    for path in sorted(case_json_paths - MADE_BY_RESOLVE):
        key, solver = schema_key(path), described["keys"][path]
        say = lambda what, ours, theirs: problems.append(f"{path}: {what}: schema {ours!r}, solver {theirs!r}")  # noqa: E731
        # type (a choice is the type of its values)
        want = KIND_TO_TYPE.get(key.kind) or ("integer" if all(isinstance(c, int) for c in key.choices) else "string")
        if want != solver["type"]:
            say("type", key.kind, solver["type"])
        # default
        theirs = "required" if solver.get("required") else solver.get("default")
        ours = "required" if key.required else key.default
        if path in DERIVED:
            if (ours, theirs) != DERIVED[path][:2]:
                say("derived default", ours, theirs)
        elif key.kind not in ("section", "list", "named") and ours != theirs:
            say("default", ours, theirs)
        elif key.kind in ("section", "list", "named") and (ours == "required") != (theirs == "required") \
                and path not in ("time", "output"):  # sections whose keys are required / one-of
            say("required", ours, theirs)
        # choices: the solver's integer range is the schema's choice of integers
        choices = solver.get("choices")
        if choices is None and key.kind == "choice" and solver["type"] == "integer":
            choices = list(range(solver["minimum"], solver["maximum"] + 1))
        if set(key.choices) != set(choices or ()):
            say("choices", sorted(key.choices, key=str), choices)
        # ranges (the solver's range of a choice of integers is compared as choices above)
        for bound in ("minimum", "above", "maximum", "below"):
            if key.kind == "choice" and solver["type"] == "integer":
                continue
            if getattr(key, bound) != solver.get(bound):
                say(bound, getattr(key, bound), solver.get(bound))
        if "unit" in solver and solver["unit"] != key.unit:
            say("unit", key.unit, solver["unit"])
    assert problems == []


def test_the_condition_kinds_are_the_schema_components(described):
    """case.json splits a condition into one entry per component with a kind: the schema's
    component keys (strain becomes the gradient of a displacement)."""
    kinds = lambda fields: {n for n, k in fields.items() if k.kind == "components"}  # noqa: E731
    keys = described["keys"]
    assert set(keys["boundary_conditions[].kind"]["choices"]) == kinds(schema.BOUNDARY_CONDITION)
    assert set(keys["initial_conditions[].kind"]["choices"]) == kinds(schema.INITIAL_CONDITION) - {"strain"}


def test_the_registries_are_the_schema_choices(described):
    registries = described["registries"]
    assert set(registries["analysis"]) == set(schema.CASE["analysis"].choices)
    assert set(registries["integrator"]) == set(schema.CASE["time"].fields["integrator"].choices)
    assert set(registries["partial_volume"]) == set(schema.CASE["discretization"].fields["partial_volume"].choices)
    assert set(registries["indenter_shape"]) == set(schema.INDENTER["shape"].choices)


@pytest.mark.parametrize("key, value, message", [("phi", 1.5, "at most 1"), ("kd", 1001, "at most 1000"),
                                                 ("tol", 1.0, "less than 1")])
def test_the_schema_enforces_the_solvers_upper_bounds(tmp_path, key, value, message):
    from pipeline.case import CaseError
    path = tmp_path / "bounds.yaml"
    path.write_text(textwrap.dedent(EVERYTHING).replace("phi: 0.5", "phi: 0.5" if key != "phi" else f"phi: {value}")
                    .replace("kd: 10", f"kd: {value}" if key == "kd" else "kd: 10")
                    .replace("tol: 0.01", f"tol: {value}" if key == "tol" else "tol: 0.01"))
    with pytest.raises(CaseError, match=f"adaptive.{key}: must be {message}"):
        load_case(str(path))
