"""Mistakes that used to be accepted silently are errors naming the .yaml line (issue 17, item 10)."""
import textwrap

import pytest

from pipeline.case import CaseError, load_case

from minimal_case import MINIMAL as BASE


def error_of(tmp_path, extra, base=BASE):
    path = tmp_path / "plate.yaml"
    path.write_text(base + textwrap.dedent(extra))
    with pytest.raises(CaseError) as info:
        load_case(str(path))
    return str(info.value)


def test_two_displacements_on_one_set_and_component(tmp_path):
    message = error_of(tmp_path, """\
        boundary_conditions:
          - set: left
            displacement: {x: 0.0, y: 0.0}
          - set: left
            displacement: {x: 0.001}
        """)
    assert ("plate.yaml:15: boundary_conditions[1].displacement.x: set 'left' component x is already given a "
            "displacement by boundary_conditions[0] (line 13); only one would act: keep one") in message


def test_displacement_in_one_item_and_velocity_in_another(tmp_path):
    message = error_of(tmp_path, """\
        boundary_conditions:
          - {set: left, displacement: {y: 0.0}}
          - {set: left, velocity: {y: 1.0}}
        """)
    assert "plate.yaml:13: boundary_conditions[1].velocity.y: set 'left' component y is already given a displacement" in message


def test_two_initial_velocities_and_one_on_a_clamped_set(tmp_path):
    message = error_of(tmp_path, """\
        boundary_conditions:
          - {set: clamped, displacement: {z: 0.0}}
        initial_conditions:
          - {set: centre, velocity: {z: 1.0}}
          - {set: centre, velocity: {z: 2.0}}
          - {set: clamped, velocity: {z: 5.0}}
        """)
    assert ("plate.yaml:15: initial_conditions[1].velocity.z: set 'centre' is given an initial velocity z twice "
            "(also initial_conditions[0], line 14); keep one") in message
    assert ("plate.yaml:16: initial_conditions[2].velocity.z: set 'clamped' component z has a prescribed "
            "displacement (boundary_conditions[0], line 12): the initial velocity would be ignored there") in message


def test_every_time_longer_than_the_run(tmp_path):
    message = error_of(tmp_path, "output: {every_time: 0.01}\n")
    assert ("plate.yaml:11: output.every_time: 0.01 s is longer than the run (time.end = 0.001 s): only the "
            "first and the last frame would be written") in message


def test_dimension_as_a_decimal_or_a_text(tmp_path):
    assert "plate.yaml:1: dimension: 2.0 is not one of 2, 3: write 2 as a whole number" in \
        error_of(tmp_path, "", BASE.replace("dimension: 2", "dimension: 2.0"))
    assert "plate.yaml:1: dimension: '2' is not one of 2, 3: write 2 without quotes" in \
        error_of(tmp_path, "", BASE.replace("dimension: 2", "dimension: \"2\""))


def test_max_steps_beyond_two_to_the_53_is_named_at_its_line(tmp_path):
    message = error_of(tmp_path, "", BASE + "  max_steps: 1e30\n")
    assert "plate.yaml:11: time.max_steps: 1e+30 is too large: a whole number is at most 2^53" in message


def test_conditions_on_different_components_and_sets_still_pass(tmp_path):
    path = tmp_path / "plate.yaml"
    path.write_text(BASE + textwrap.dedent("""\
        boundary_conditions:
          - {set: left, displacement: {x: 0.0}}
          - {set: left, velocity: {y: 1.0}}
          - {set: right, displacement: {x: 0.0}}
        initial_conditions:
          - {set: centre, velocity: {z: 1.0}}
          - {set: left, velocity: {z: 1.0}}
        """))
    case = load_case(str(path))
    assert len(case["boundary_conditions"]) == 3 and len(case["initial_conditions"]) == 2


def test_a_gmsh_parameter_the_geo_never_uses(tmp_path):
    """gmsh ignores `-setnumber` for a name the .geo does not read: the mesh stage says so first."""
    import os
    import shutil
    import subprocess
    import sys
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    folder = tmp_path / "membrane"
    folder.mkdir()
    shutil.copy(os.path.join(root, "cases", "membrane", "membrane.geo"), folder)
    text = open(os.path.join(root, "cases", "membrane", "membrane.yaml"), encoding="utf-8").read()
    (folder / "membrane.yaml").write_text(text.replace("{L: 0.05, r: 0.006, lc: 0.002}",
                                                       "{L: 0.05, radius: 0.006, lc: 0.002}"))
    result = subprocess.run([sys.executable, "-m", "pipeline.run", "mesh", str(folder / "membrane.yaml"),
                             str(folder / "membrane.geo"), str(tmp_path / "mesh.msh")], cwd=root,
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 2, result.stderr
    assert (f"membrane.yaml:10: geometry.parameters.radius: {folder / 'membrane.geo'} never uses 'radius', so "
            "gmsh would ignore it") in result.stderr
    assert not (tmp_path / "mesh.msh").exists()
