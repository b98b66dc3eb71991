"""Every refusal of pdsolve's case reader (solver/src/io/case_reader.cpp) and of its integrators'
set-up that the case file alone decides is made by `check` too, at the .yaml line (issue 36, item 14).

Before, `mixed.start: verlet`, `quasi_static.linear_solver: bogus`, `dt_min > dt_max` and the others
below passed `make check` and preprocess, and only pdsolve refused them, naming case.json. Each case
here is checked twice: `check` refuses the YAML at its line, and the solver refuses the same setting
in a case.json written from a valid case (so the list is the solver's, not a guess).
"""
import json
import os
import subprocess
import sys

import pytest

from pipeline.case import CaseError, load_case
from pipeline.resolve import resolve
from preprocess.node_file import write_node_file

from common.paths import REPOSITORY as ROOT
from minimal_case import MINIMAL, lattice_cloud

# name: (YAML appended to MINIMAL, the error's line, the error after "plate.yaml:LINE: ",
#        the case.json change that the solver refuses, a text of the solver's message)
CASES = {
    "mixed_start_verlet": (
        "time:\n  end: 1.0e-3\n  integrator: mixed\nmixed:\n  start: verlet\n", 13,
        "mixed.start: 'verlet' is not one of 'quasi_static', 'implicit'",
        {"time.integrator": "mixed", "mixed.start": "verlet"}, "mixed.start: unknown value 'verlet'"),
    "quasi_static_linear_solver_bogus": (
        "quasi_static:\n  linear_solver: bogus\n", 12,
        "quasi_static.linear_solver: 'bogus' is not one of 'auto', 'direct', 'cg'",
        {"quasi_static.linear_solver": "bogus"}, "quasi_static.linear_solver: unknown value 'bogus'"),
    "quasi_static_preconditioner_bogus": (
        "quasi_static:\n  preconditioner: amgg\n", 12,
        "quasi_static.preconditioner: 'amgg' is not one of 'auto', 'block_jacobi', 'amg' (did you mean 'amg'?)",
        {"quasi_static.preconditioner": "amgg"}, "quasi_static.preconditioner: unknown value 'amgg'"),
    "implicit_linear_solver_bogus": (
        "implicit:\n  linear_solver: lu\n", 12,
        "implicit.linear_solver: 'lu' is not one of 'auto', 'direct', 'cg'",
        {"implicit.linear_solver": "lu"}, "implicit.linear_solver: unknown value 'lu'"),
    "quasi_static_dt_min_above_dt_max": (
        "quasi_static:\n  dt_min: 1.0e-4\n  dt_max: 1.0e-5\n", 12,
        "quasi_static.dt_min: dt_min 0.0001 s is larger than dt_max 1e-05 s",
        {"quasi_static.dt_min": 1e-4, "quasi_static.dt_max": 1e-5}, "quasi_static.dt_min: is larger than"),
    "quasi_static_dt_min_above_default_dt_max": (
        "time:\n  end: 1.0e-3\n  integrator: quasi_static\nquasi_static:\n  dt_min: 2.0e-4\n", 13,
        "quasi_static.dt_min: dt_min 0.0002 s is larger than the default dt_max 0.0001 s (time.end/10)",
        {"time.integrator": "quasi_static", "quasi_static.dt_min": 2e-4}, "quasi_static.dt_min = 0.0002 s is above dt_max"),
    "implicit_dt_min_above_dt_max": (
        "implicit:\n  dt_min: 1.0e-4\n  dt_max: 1.0e-5\n", 12,
        "implicit.dt_min: dt_min 0.0001 s is larger than dt_max 1e-05 s",
        {"implicit.dt_min": 1e-4, "implicit.dt_max": 1e-5}, "implicit.dt_min: is larger than"),
    "implicit_dt_min_above_default_dt_max": (
        "time:\n  end: 1.0e-3\n  integrator: implicit\nimplicit:\n  dt_min: 2.0e-4\n", 13,
        "implicit.dt_min: dt_min 0.0002 s is larger than the default dt_max 0.0001 s (time.end/10)",
        {"time.integrator": "implicit", "implicit.dt_min": 2e-4}, "implicit.dt_min = 0.0002 s is above dt_max"),
    "implicit_dt_initial_above_dt_max": (
        "implicit:\n  dt_initial: 1.0e-4\n  dt_max: 1.0e-5\n", 12,
        "implicit.dt_initial: dt_initial 0.0001 s is larger than dt_max 1e-05 s",
        {"implicit.dt_initial": 1e-4, "implicit.dt_max": 1e-5}, "implicit.dt_initial: is larger than"),
    "implicit_dt_initial_below_dt_min": (
        "implicit:\n  dt_initial: 1.0e-7\n  dt_min: 1.0e-6\n", 12,
        "implicit.dt_initial: dt_initial 1e-07 s is smaller than dt_min 1e-06 s",
        {"implicit.dt_initial": 1e-7, "implicit.dt_min": 1e-6}, "implicit.dt_initial: is smaller than"),
    "output_field_twice": (
        "output:\n  fields: [displacement, damage, damage]\n", 12,
        "output.fields[2]: 'damage' is listed twice",
        {"output.fields": ["displacement", "damage", "damage"]}, "output.fields: 'damage' is listed twice"),
    "damping_with_quasi_static": (
        "time:\n  end: 1.0e-3\n  integrator: quasi_static\ndamping: 10\n", 12,
        "damping: 10 1/s, but the quasi_static integrator solves load steps for equilibrium",
        {"time.integrator": "quasi_static", "damping": 10.0}, "damping: quasi_static solves for equilibrium"),
    "damping_with_mixed_from_quasi_static": (
        "time:\n  end: 1.0e-3\n  integrator: mixed\ndamping: 10\n", 12,
        "damping: 10 1/s, but the mixed integrator solves load steps for equilibrium",
        {"time.integrator": "mixed", "damping": 10.0}, "damping: quasi_static solves for equilibrium"),
    "direct_with_contact": (
        "time:\n  end: 1.0e-3\n  integrator: quasi_static\nquasi_static:\n  linear_solver: direct\n"
        "contact:\n  enabled: 'on'\n", 13,
        "quasi_static.linear_solver: direct factorises the assembled tangent stiffness, and contact.enabled is on",
        {"time.integrator": "quasi_static", "quasi_static.linear_solver": "direct", "contact.enabled": "on"},
        "quasi_static.linear_solver: direct needs an assembled tangent, which contact does not have"),
    "indenter_normal_overflows": (
        "indenters:\n  - {name: wall, shape: plane, centre: [0, 0], normal: [1.0e+200, 1.0e+200], "
        "stiffness: 1.0e+12}\n", 12,
        "indenters[0].normal: its length overflows a double",
        {"indenters": [{"name": "wall", "shape": "plane", "centre": [0.0, 0.0, 0.0], "velocity": [0.0, 0.0, 0.0],
                        "normal": [1e200, 1e200, 0.0], "stiffness": 1e12}]},
        "indenters[0].normal: must be a non-zero vector"),
}


def yaml_of(name: str) -> str:
    text, *_ = CASES[name]
    if text.startswith("time:"):  # replaces MINIMAL's time section (its last lines)
        return MINIMAL.replace("time:\n  end: 1.0e-3\n", "") + text
    return MINIMAL + text


@pytest.mark.parametrize("name", sorted(CASES))
def test_check_refuses_at_the_yaml_line(tmp_path, name):
    _, line, message, _, _ = CASES[name]
    path = tmp_path / "plate.yaml"
    path.write_text(yaml_of(name))
    result = subprocess.run([sys.executable, "-m", "pipeline.run", "check", str(path)], cwd=ROOT,
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    assert f"error: {path}:{line}: {message}" in result.stderr, result.stderr


def set_dotted(data: dict, dotted: str, value):
    *parents, last = dotted.split(".")
    for part in parents:
        data = data.setdefault(part, {})
    data[last] = value


@pytest.fixture(scope="module")
def valid_case_json(tmp_path_factory):
    """A resolved case.json of MINIMAL and its 12 × 10 lattice, which pdsolve runs."""
    folder = tmp_path_factory.mktemp("solver_only")
    (folder / "plate.yaml").write_text(MINIMAL)
    cloud = lattice_cloud()
    write_node_file(str(folder / "nodes.vtu"), cloud)
    return folder, resolve(load_case(str(folder / "plate.yaml")), node_sets=[], grid_spacing=0.001,
                           nodes_file="nodes.vtu")


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_solver_refuses_the_same_setting(valid_case_json, pdsolve, name):
    folder, resolved = valid_case_json
    _, _, _, change, solver_says = CASES[name]
    case = json.loads(json.dumps(resolved))
    case["time"]["max_steps"] = 5
    for dotted, value in change.items():
        set_dotted(case, dotted, value)
    path = folder / f"{name}.json"
    path.write_text(json.dumps(case))
    result = subprocess.run([pdsolve, str(path), "--threads", "1"], capture_output=True, text=True, timeout=60,
                            cwd=folder)
    assert result.returncode == 1, (result.returncode, result.stderr[-2000:])
    assert solver_says in result.stderr, result.stderr[-2000:]


def test_a_valid_mixed_start_and_solver_choices_still_load(tmp_path):
    path = tmp_path / "plate.yaml"
    path.write_text(MINIMAL.replace("time:\n  end: 1.0e-3\n", "") +
                    "time:\n  end: 1.0e-3\n  integrator: mixed\nmixed:\n  start: implicit\n"
                    "implicit:\n  linear_solver: direct\n  dt_initial: 1.0e-6\n  dt_min: 1.0e-7\n"
                    "quasi_static:\n  preconditioner: block_jacobi\n")
    case = load_case(str(path))
    assert case["mixed"]["start"] == "implicit" and case["implicit"]["linear_solver"] == "direct"
    with pytest.raises(CaseError):
        path.write_text(MINIMAL + "mixed:\n  start: 'implicit '\n")
        load_case(str(path))
