"""The case-file loader: defaults, and errors that name the file, the line and the key."""
import os
import textwrap

import pytest

from pipeline import schema
from pipeline.case import CaseError, load_case
from pipeline.resolve import check_set_names, resolve

from minimal_case import MINIMAL

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))



def write(tmp_path, text, name="plate.yaml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return str(path)


def error_of(tmp_path, text):
    with pytest.raises(CaseError) as info:
        load_case(write(tmp_path, text))
    return str(info.value)


def test_defaults_are_filled_in(tmp_path):
    case = load_case(write(tmp_path, MINIMAL))
    assert case["analysis"] == "plane_stress"
    assert case["discretization"]["method"] == "lattice"
    assert case["discretization"]["horizon_factor"] == 3.015
    assert case["time"]["dt"] == "stable"
    assert case["time"]["safety_factor"] == 0.8
    assert case["output"]["every_time"] == pytest.approx(1.0e-3 / 50)
    assert case["materials"]["plate"]["fracture_energy"] is None


def test_case_name_is_folder_and_variant(tmp_path):
    folder = tmp_path / "plate"
    folder.mkdir()
    assert load_case(write(folder, MINIMAL, "plate.yaml"))["_name"] == "plate"
    assert load_case(write(folder, MINIMAL, "fine.yaml"))["_name"] == "plate-fine"


def test_unknown_key_names_line_and_closest_key(tmp_path):
    text = MINIMAL.replace("  end: 1.0e-3", "  end: 1.0e-3\n  safety_factr: 0.5")
    message = error_of(tmp_path, text)
    assert "plate.yaml:11: time.safety_factr: unknown key (did you mean 'safety_factor'?)" in message


def test_missing_required_key(tmp_path):
    message = error_of(tmp_path, MINIMAL.replace("    density: 2000\n", ""))
    assert "plate.yaml:6: materials.plate.density: missing required key" in message


def test_wrong_type_and_out_of_range_are_all_reported(tmp_path):
    text = (MINIMAL.replace("youngs_modulus: 1.0e9", "youngs_modulus: -5")
            .replace("dx: 0.001", "dx: fine"))
    message = error_of(tmp_path, text)
    assert "plate.yaml:4: discretization.dx: expected a number [m], got 'fine'" in message
    assert "plate.yaml:8: materials.plate.youngs_modulus: must be greater than 0 [Pa], got -5" in message


def test_unknown_choice_suggests(tmp_path):
    message = error_of(tmp_path, MINIMAL + "analysis: plane_stres\n")
    assert "plate.yaml:11: analysis: 'plane_stres' is not one of" in message
    assert "did you mean 'plane_stress'?" in message


def test_2d_needs_thickness(tmp_path):
    message = error_of(tmp_path, MINIMAL.replace("thickness: 0.001\n", ""))
    assert "thickness: a 2D case needs thickness" in message


def test_horizon_smaller_than_dx(tmp_path):
    message = error_of(tmp_path, MINIMAL.replace("dx: 0.001", "dx: 0.001\n  horizon: 0.0005"))
    assert "discretization.horizon: horizon 0.0005 m is smaller than dx 0.001 m" in message


def test_time_table_must_increase(tmp_path):
    text = MINIMAL + textwrap.dedent("""\
        boundary_conditions:
          - set: left
            velocity: {x: [[0.0, 0.0], [0.0, 1.0]]}
        """)
    message = error_of(tmp_path, text)
    assert "boundary_conditions[0].velocity.x: table times must increase strictly" in message


def test_displacement_and_velocity_on_same_component(tmp_path):
    text = MINIMAL + textwrap.dedent("""\
        boundary_conditions:
          - set: left
            displacement: {x: 0.0}
            velocity: {x: 1.0}
        """)
    message = error_of(tmp_path, text)
    assert "component x is given both a displacement and a velocity" in message


def test_invalid_yaml_names_line(tmp_path):
    message = error_of(tmp_path, MINIMAL + "time: [unclosed\n")
    assert message.startswith(str(tmp_path / "plate.yaml") + ":")
    assert "not valid YAML" in message


def test_duplicate_key(tmp_path):
    message = error_of(tmp_path, MINIMAL + "damping: 1.0\ndamping: 2.0\n")
    assert "plate.yaml:12: key 'damping' appears twice" in message


def test_missing_node_set_lists_existing(tmp_path):
    text = MINIMAL + textwrap.dedent("""\
        boundary_conditions:
          - set: lefft
            displacement: {x: 0.0}
        """)
    case = load_case(write(tmp_path, text))
    with pytest.raises(CaseError) as info:
        check_set_names(case, ["left", "right", "plate"])
    message = str(info.value)
    assert "plate.yaml:12: node set 'lefft' is not a physical group of the mesh (did you mean 'left'?)" in message
    assert "the mesh has: left, plate, right" in message


def test_resolve_expands_components_and_tables(tmp_path):
    text = MINIMAL + textwrap.dedent("""\
        boundary_conditions:
          - set: left
            displacement: {x: 0.0, z: [[0.0, 0.0], [1.0e-3, 2.0e-5]]}
        initial_conditions:
          - set: plate
            velocity: {y: 3.5}
        """)
    case = load_case(write(tmp_path, text))
    resolved = resolve(case, node_sets=["left", "plate"], grid_spacing=0.001, nodes_file="nodes.vtu")
    assert resolved["horizon"] == pytest.approx(3.015e-3)
    assert resolved["boundary_conditions"] == [
        {"set": "left", "kind": "displacement", "component": 0, "times": [0.0], "values": [0.0]},
        {"set": "left", "kind": "displacement", "component": 2, "times": [0.0, 1.0e-3],
         "values": [0.0, 2.0e-5]},
    ]
    assert resolved["initial_conditions"] == [
        {"set": "plate", "kind": "velocity", "component": 1, "value": 3.5}]
    assert resolved["blocks"][0]["id"] == 1 and resolved["blocks"][0]["name"] == "plate"


def test_membrane_case_is_valid():
    case = load_case(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"))
    assert case["dimension"] == 2 and "membrane" in case["materials"]


def test_case_file_reference_is_generated_from_schema():
    with open(os.path.join(ROOT, "docs", "case-file.md"), encoding="utf-8") as stream:
        assert stream.read() == schema.markdown(), "regenerate: /usr/bin/python3 -m pipeline.schema > docs/case-file.md"


def test_adaptive_section_defaults_and_resolution(tmp_path):
    case = load_case(write(tmp_path, MINIMAL.replace("  end: 1.0e-3", "  end: 1.0e-3\n  integrator: adaptive")))
    assert case["time"]["integrator"] == "adaptive"
    assert case["adaptive"] == {"tol": 1e-3, "kd": 20, "p": 3.0, "phi": 1.0,
                                "dt_initial": None, "dt_min": None, "dt_max": None}
    resolved = resolve(case, node_sets=[], grid_spacing=0.001, nodes_file="nodes.vtu")
    assert resolved["adaptive"]["kd"] == 20 and resolved["time"]["integrator"] == "adaptive"


def test_bad_adaptive_values_name_line_and_range(tmp_path):
    text = MINIMAL + "adaptive:\n  phi: 0.3\n  kd: 0\n  tol: 2.0\n  dt_min: 1.0e-6\n  dt_max: 1.0e-7\n"
    message = error_of(tmp_path, text)
    assert "plate.yaml:12: adaptive.phi: must be at least 0.5, got 0.3" in message
    assert "plate.yaml:13: adaptive.kd: must be at least 1, got 0" in message
    text = MINIMAL + "adaptive:\n  phi: 1.5\n  tol: 2.0\n  dt_min: 1.0e-6\n  dt_max: 1.0e-7\n"
    message = error_of(tmp_path, text)
    assert "plate.yaml:12: adaptive.phi: must be at most 1, got 1.5" in message  # schema maximum
    assert "plate.yaml:13: adaptive.tol: must be less than 1, got 2" in message  # schema below
    # the cross-checks run once every value is in its range
    message = error_of(tmp_path, MINIMAL + "adaptive:\n  phi: 1.0\n  tol: 0.5\n  dt_min: 1.0e-6\n  dt_max: 1.0e-7\n")
    assert "plate.yaml:14: adaptive.dt_min: dt_min 1e-06 s is larger than dt_max 1e-07 s" in message


def test_dt_exact_is_a_known_rule(tmp_path):
    case = load_case(write(tmp_path, MINIMAL.replace("  end: 1.0e-3", "  end: 1.0e-3\n  dt: exact")))
    assert case["time"]["dt"] == "exact"
    message = error_of(tmp_path, MINIMAL.replace("  end: 1.0e-3", "  end: 1.0e-3\n  dt: exakt"))
    assert "time.dt: 'exakt' is not one of 'stable', 'exact'" in message


@pytest.mark.parametrize("tol, kd", [("0.0", "0"), ("-1.0e-3", "-2")])
def test_adaptive_tol_not_positive_and_kd_below_one_are_rejected(tmp_path, tol, kd):
    # issue 3: TOL is a relative error (> 0) and K_d a count of iterations (≥ 1).
    message = error_of(tmp_path, MINIMAL + f"adaptive:\n  tol: {tol}\n  kd: {kd}\n")
    assert f"plate.yaml:12: adaptive.tol: must be greater than 0, got {float(tol):g}" in message
    assert f"plate.yaml:13: adaptive.kd: must be at least 1, got {int(kd)}" in message


def test_unknown_output_field_names_line_and_lists_the_valid_ones(tmp_path):
    text = MINIMAL + "output:\n  fields: [displacement, velocty]\n"
    message = error_of(tmp_path, text)
    assert "plate.yaml:12: output.fields[1]: unknown name 'velocty' (did you mean 'velocity'?); " \
           "valid: displacement, velocity, damage, block" in message


def test_output_format_defaults_are_the_compact_frames(tmp_path):
    output = load_case(write(tmp_path, MINIMAL))["output"]
    assert (output["precision"], output["compression"], output["gmsh"]) == ("float32", "zlib", "figures")
    assert output["fields"] == ["displacement", "velocity", "damage", "block"]
    assert "precision: 'float16' is not one of 'float32', 'float64'" in \
        error_of(tmp_path, MINIMAL + "output:\n  precision: float16\n")


def test_surface_correction_is_none_by_default_and_a_choice(tmp_path):
    assert load_case(write(tmp_path, MINIMAL))["discretization"]["surface_correction"] == "none"
    text = MINIMAL.replace("  dx: 0.001\n", "  dx: 0.001\n  surface_correction: volum\n")
    message = error_of(tmp_path, text)
    assert "plate.yaml:5: discretization.surface_correction: 'volum' is not one of" in message
    case = load_case(write(tmp_path, MINIMAL.replace("  dx: 0.001\n", "  dx: 0.001\n  surface_correction: energy\n")))
    assert case["discretization"]["surface_correction"] == "energy"
