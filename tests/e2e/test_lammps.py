"""One LAMMPS peri/pmb deck reproduced side by side (docs/lammps.md): a small brick pulled apart
at both ends, run by Debian's LAMMPS (`lmp`) and by our pipeline from the equivalent case file.

The two inputs say the same thing in each code's words: a simple-cubic lattice through the origin
(discretization.origin, LAMMPS's `lattice sc`), the horizon and LAMMPS's partial volumes
(partial_volume: lammps), c and s00 given directly (micromodulus, critical_stretch), LAMMPS's
critical-stretch rule (critical_stretch_alpha) and its breaking order (breaking_order: lammps),
the end layers moving at a constant velocity (LAMMPS: velocity + fix setforce 0 0 0).

- Until the first bond breaks the deformation is linear, and the positions agree to round-off:
  LAMMPS integrates x, we integrate u = x − X, so the last bits differ.
- Then both codes break bonds by the same rule. With breaking_order: lammps the same bonds break in
  the same steps (on this deck through the whole fracture: no stretch lands within round-off of its
  threshold); with the thesis order (a bond over s0 gives no force in the step it breaks) the
  positions depart from LAMMPS's at the first break and the damage follows.

A second deck (two bricks colliding) holds our contact section to LAMMPS's short-range force.

Skips when the `lmp` binary is absent (Debian's `lammps` package: pipeline/install-deps.sh, which
`make test` runs, installs it); installs nothing itself.
"""
import csv
import os
import shutil
import subprocess
import textwrap

import meshio
import numpy as np
import pytest
import yaml

from e2e_support import PY, ROOT, SOLVER, new_case_folder  # noqa: E402

LMP = shutil.which("lmp")
# slow: a comparison with another code, run by make validate. In make test the gtests PmbLammps.*
# hold LAMMPS's α rule and breaking order, test_mpi_lammps_rule.py their keys end to end (1-3 ranks),
# the Contact gtests the short-range force.
pytestmark = [pytest.mark.skipif(
    LMP is None, reason="LAMMPS is not installed (no `lmp` on PATH): Debian's `lammps` package; "
    "`sh pipeline/install-deps.sh` (run by make test) installs it"), pytest.mark.slow]

DX = 1.0e-3                      # lattice constant a [m]
NX, NY, NZ = 16, 5, 5            # nodes per axis: LAMMPS's atoms at k·a, k = 0 … N − 1
HORIZON = 3.0002 * DX            # δ, as in LAMMPS's PERI examples (just over 3a)
MICROMODULUS = 3.3936e21         # c [N/m⁶] (about 12E/(πδ⁴) for E = 72 GPa)
S00 = 1.0e-3                     # critical stretch s00
ALPHA = 0.25                     # α of s0_i = s00 − α·min_j s_ij (LAMMPS's PERI examples)
DENSITY = 2440.0                 # [kg/m³]
SPEED = 1.0                      # end layers at ∓SPEED in x [m/s]
DT = 5.0e-8                      # [s], about a quarter of a/c_wave
STEPS = 300
EVERY = 10                       # a frame / a dump every EVERY steps


def lammps_deck():
    hi = [n - 0.5 for n in (NX, NY, NZ)]
    return textwrap.dedent(f"""\
        units si
        boundary s s s
        atom_style peri
        atom_modify map array
        lattice sc {DX!r}
        region box block -0.5 {hi[0]} -0.5 {hi[1]} -0.5 {hi[2]}
        create_box 1 box
        create_atoms 1 region box
        pair_style peri/pmb
        pair_coeff * * {MICROMODULUS!r} {HORIZON!r} {S00!r} {ALPHA!r}
        set group all density {DENSITY!r}
        set group all volume {DX ** 3!r}
        region left block INF 0.5 INF INF INF INF
        region right block {NX - 1.5} INF INF INF INF INF
        group left region left
        group right region right
        velocity left set {-SPEED!r} 0.0 0.0 units box
        velocity right set {SPEED!r} 0.0 0.0 units box
        fix hold_left left setforce 0.0 0.0 0.0
        fix hold_right right setforce 0.0 0.0 0.0
        fix move all nve
        neighbor {0.3 * DX!r} bin
        neigh_modify every 1 delay 0 check yes
        compute damage all damage/atom
        timestep {DT!r}
        dump positions all custom {EVERY} dump.txt id x y z c_damage
        dump_modify positions format float %.17g sort id
        thermo {EVERY}
        thermo_style custom step pe ke
        thermo_modify format float %.17g
        run {STEPS}
        """)


def read_thermo(text):
    """{step: (pe, ke)} from LAMMPS's screen output (thermo_style custom step pe ke)."""
    rows, on = {}, False
    for line in text.splitlines():
        words = line.split()
        if words[:3] == ["Step", "PotEng", "KinEng"]:
            on = True
        elif on and len(words) == 3 and words[0].isdigit():
            rows[int(words[0])] = (float(words[1]), float(words[2]))
        else:
            on = False
    return rows


def read_dump(path):
    """{step: (positions (n, 3), damage (n,))} in atom-id order, from a LAMMPS text dump."""
    frames, lines = {}, open(path, encoding="utf-8").read().splitlines()
    k = 0
    while k < len(lines):
        assert lines[k] == "ITEM: TIMESTEP"
        step, count = int(lines[k + 1]), int(lines[k + 3])
        rows = np.array([[float(v) for v in line.split()] for line in lines[k + 9:k + 9 + count]])
        frames[step] = (rows[:, 1:4], rows[:, 4])
        k += 9 + count
    return frames


GEO = f"""\
SetFactory("OpenCASCADE");
// The brick LAMMPS's region covers: half a lattice constant beyond the outer atoms on every side.
Box(1) = {{{-0.5 * DX!r}, {-0.5 * DX!r}, {-0.5 * DX!r}, {NX * DX!r}, {NY * DX!r}, {NZ * DX!r}}};
e = {1e-3 * DX!r};
Physical Volume("brick") = {{1}};
Physical Surface("left") = Surface In BoundingBox{{{-0.5 * DX!r} - e, -1, -1, {-0.5 * DX!r} + e, 1, 1}};
Physical Surface("right") = Surface In BoundingBox{{{(NX - 0.5) * DX!r} - e, -1, -1, {(NX - 0.5) * DX!r} + e, 1, 1}};
Mesh.MeshSizeMax = {2 * DX!r};
"""


def our_case(order):
    return {
        "title": f"LAMMPS peri/pmb brick, breaking order {order}",
        "dimension": 3,
        "discretization": {"dx": DX, "horizon": HORIZON, "origin": [0.0, 0.0, 0.0], "partial_volume": "lammps"},
        "materials": {"brick": {"density": DENSITY, "micromodulus": MICROMODULUS, "critical_stretch": S00,
                                "critical_stretch_alpha": ALPHA}},
        "breaking_order": order,
        "boundary_conditions": [{"set": "left", "velocity": {"x": -SPEED, "y": 0.0, "z": 0.0}},
                                {"set": "right", "velocity": {"x": SPEED, "y": 0.0, "z": 0.0}}],
        "time": {"end": (STEPS + 0.5) * DT, "dt": DT, "max_steps": STEPS},
        "output": {"every_steps": EVERY, "precision": "float64", "fields": ["displacement", "damage"],
                   "gmsh": "none"},
    }


def run_ours(work, case_dir, order):
    name = f"brick_{order}"
    yaml_path = case_dir / f"{name}.yaml"
    yaml_path.write_text(yaml.safe_dump(our_case(order)))
    out = work / name
    env = dict(os.environ, PYTHONPATH=ROOT)
    for args in ((PY, "-m", "pipeline.run", "mesh", str(yaml_path), str(case_dir / "brick.geo"), str(out / "mesh.msh")),
                 (PY, "-m", "pipeline.run", "preprocess", str(yaml_path), str(out / "mesh.msh"), str(out)),
                 (SOLVER, str(out / "case.json"), "--quiet")):
        result = subprocess.run(list(args), cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
        assert result.returncode == 0, f"{' '.join(args)} failed:\n{result.stdout}\n{result.stderr}"
    with open(out / "history.csv", encoding="utf-8") as stream:
        history = {int(row["step"]): row for row in csv.DictReader(stream)}
    frames = {"history": history}
    for k in range(STEPS // EVERY + 1):
        mesh = meshio.read(out / "frames" / f"frame_{k:06d}.vtu")
        frames[k * EVERY] = (mesh.points + mesh.point_data["displacement"], mesh.point_data["damage"].ravel(),
                             mesh.points)
    return frames


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "lammps", "brick")
    (case_dir / "brick.geo").write_text(GEO)
    lammps_dir = work / "lammps"
    lammps_dir.mkdir()
    (lammps_dir / "in.brick").write_text(lammps_deck())
    result = subprocess.run([LMP, "-in", "in.brick", "-log", "log.lammps"], cwd=lammps_dir, capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, f"lmp failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
    theirs = read_dump(lammps_dir / "dump.txt")
    theirs_thermo = read_thermo(result.stdout)
    ours = {order: run_ours(work, case_dir, order) for order in ("lammps", "thesis")}
    history = ours["lammps"].pop("history")
    ours["thesis"].pop("history")
    # Our nodes in LAMMPS's atom order: both sit at k·a, so the reference positions match exactly.
    start = theirs[0][0]
    index = {tuple(np.rint(p / DX).astype(int)): i for i, p in enumerate(start)}
    for order, frames in ours.items():
        reference = frames[0][2]
        perm = np.array([index[tuple(np.rint(p / DX).astype(int))] for p in reference])
        assert len(perm) == len(start) == NX * NY * NZ and len(set(perm)) == len(perm)
        order_of = np.argsort(perm)  # ours[order_of] is in LAMMPS's order
        ours[order] = {step: (y[order_of], d[order_of], x[order_of]) for step, (y, d, x) in frames.items()}
    return theirs, ours, (theirs_thermo, history)


def first_damage_step(frames):
    return min(step for step, (_, damage, *rest) in frames.items() if np.any(damage > 0))


def test_the_lattices_are_the_same_points(runs):
    """discretization.origin puts our nodes where LAMMPS's lattice puts its atoms: bitwise k·a."""
    theirs, ours, _ = runs
    assert np.array_equal(ours["lammps"][0][2], theirs[0][0])


def test_positions_agree_to_round_off_until_bonds_break(runs):
    theirs, ours, _ = runs
    first = min(first_damage_step(theirs), first_damage_step(ours["lammps"]))
    assert first > 5 * EVERY, "bonds break too early for a linear stretch to compare"
    length = (NX - 1) * DX
    worst = 0.0
    for step in sorted(theirs):
        if step >= first:
            break
        worst = max(worst, float(np.max(np.abs(ours["lammps"][step][0] - theirs[step][0]))) / length)
        # the thesis order is the same motion while nothing breaks
        assert np.array_equal(ours["thesis"][step][0], ours["lammps"][step][0])
    print(f"first damage at step {first}; max |Δx|/L before it: {worst:.3e}")
    assert worst < 1e-13


def test_with_the_lammps_order_the_whole_run_is_lammps_s(runs):
    """breaking_order: lammps with LAMMPS's α rule: the same bonds break in the same steps, so the
    damage is the same at every frame and the positions stay within round-off through the fracture
    (measured: 5.9e-15 of the length at step 300, damage equal at all 31 frames)."""
    theirs, ours, _ = runs
    length = (NX - 1) * DX
    assert np.sum(theirs[STEPS][1]) > 10.0  # the brick has broken: this is a fracture, not elasticity
    for step in sorted(theirs):
        y, damage, _ = ours["lammps"][step]
        assert np.max(np.abs(damage - theirs[step][1])) <= 1e-12, f"damage differs at step {step}"
        assert np.max(np.abs(y - theirs[step][0])) / length < 1e-13, f"positions differ at step {step}"


def test_with_the_thesis_order_the_run_departs_from_lammps_at_the_first_break(runs):
    """breaking_order: thesis drops a bond's force in the step it breaks, a step before LAMMPS
    does: the positions depart from LAMMPS's at the first break and the damage follows."""
    theirs, ours, _ = runs
    first = first_damage_step(theirs)
    length = (NX - 1) * DX
    departed = {step: float(np.max(np.abs(ours["thesis"][step][0] - theirs[step][0]))) / length
                for step in sorted(theirs)}
    damage_differs = [step for step in sorted(theirs)
                      if np.max(np.abs(ours["thesis"][step][1] - theirs[step][1])) > 1e-12]
    print(f"thesis order: max |Δx|/L {departed[first]:.2e} at step {first}, {max(departed.values()):.2e} at most; "
          f"damage differs at steps {damage_differs}")
    assert all(departed[step] < 1e-13 for step in departed if step < first)
    assert departed[first] > 1e-9
    assert damage_differs and min(damage_differs) > first


def test_energies_are_lammps_s_thermo_times_the_node_volume(runs):
    """LAMMPS's pe and ke sum energy densities over atoms (rmass is ρ, f a force density): times
    V = a³ they are our strain_energy and kinetic_energy [J], step by step through the fracture
    (measured: 7.8e-12 and 6.1e-12 relative at most; the stretch s ~ 1e-3 carries the positions'
    round-off of ~1e-15 relative into s² at ~1e-12)."""
    _, _, (thermo, history) = runs
    volume = DX ** 3
    assert sorted(thermo) == list(range(0, STEPS + 1, EVERY))
    for step, (pe, ke) in thermo.items():
        ours = history[step]
        strain, kinetic = float(ours["strain_energy"]), float(ours["kinetic_energy"])
        assert pe * volume == pytest.approx(strain, rel=1e-10, abs=1e-30), step
        assert ke * volume == pytest.approx(kinetic, rel=1e-10), step


# -- Contact: two bricks collide -------------------------------------------------------------------
# LAMMPS peri/pmb's short-range force (15·c·V_j·(r − d)/δ for r < d = min(0.9·r0, 1.35a), on every
# neighbour pair) against our contact section (stiffness_factor 15, d = 1.35dx between blocks): two
# unbreakable 6 × 4 × 4 bricks 4a apart (more than δ: no bond between them), one flying at the
# other at 100 m/s, closing to within 1.35a and bouncing back.
HIT_N = 6           # layers per brick along x
HIT_GAP = 4         # lattice constants between the facing layers
HIT_SPEED = 100.0   # [m/s]
HIT_STEPS = 1000
HIT_EVERY = 20


def collision_deck():
    b0, b1, hi_y, hi_z = HIT_N - 1 + HIT_GAP - 0.5, 2 * HIT_N + HIT_GAP - 1.5, NY - 0.5, NZ - 0.5
    return textwrap.dedent(f"""\
        units si
        boundary s s s
        atom_style peri
        atom_modify map array
        lattice sc {DX!r}
        region box block -0.5 {b1} -0.5 {hi_y} -0.5 {hi_z}
        create_box 1 box
        region a block -0.5 {HIT_N - 0.5} -0.5 {hi_y} -0.5 {hi_z}
        region b block {b0} {b1} -0.5 {hi_y} -0.5 {hi_z}
        create_atoms 1 region a
        create_atoms 1 region b
        pair_style peri/pmb
        pair_coeff * * {MICROMODULUS!r} {HORIZON!r} 1.0 0.0
        set group all density {DENSITY!r}
        set group all volume {DX ** 3!r}
        group b region b
        velocity b set {-HIT_SPEED!r} 0.0 0.0 units box
        fix move all nve
        neighbor {0.3 * DX!r} bin
        neigh_modify every 1 delay 0 check yes
        compute damage all damage/atom
        timestep {DT!r}
        dump positions all custom {HIT_EVERY} dump.txt id x y z c_damage
        dump_modify positions format float %.17g sort id
        run {HIT_STEPS}
        """)


def collision_case():
    return {
        "title": "two bricks collide (LAMMPS peri/pmb short-range force)",
        "dimension": 3,
        "discretization": {"dx": DX, "horizon": HORIZON, "origin": [0.0, 0.0, 0.0], "partial_volume": "lammps"},
        "materials": {"a": {"density": DENSITY, "micromodulus": MICROMODULUS},
                      "b": {"density": DENSITY, "micromodulus": MICROMODULUS}},
        "initial_conditions": [{"set": "b", "velocity": {"x": -HIT_SPEED}}],
        "contact": {"enabled": "on", "stiffness_factor": 15.0},
        "time": {"end": (HIT_STEPS + 0.5) * DT, "dt": DT, "max_steps": HIT_STEPS},
        "output": {"every_steps": HIT_EVERY, "precision": "float64", "fields": ["displacement"], "gmsh": "none"},
    }


@pytest.fixture(scope="module")
def collision(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "lammps_hit", "hit")
    b0 = (HIT_N - 1 + HIT_GAP - 0.5) * DX
    (case_dir / "hit.geo").write_text(textwrap.dedent(f"""\
        SetFactory("OpenCASCADE");
        Box(1) = {{{-0.5 * DX!r}, {-0.5 * DX!r}, {-0.5 * DX!r}, {HIT_N * DX!r}, {NY * DX!r}, {NZ * DX!r}}};
        Box(2) = {{{b0!r}, {-0.5 * DX!r}, {-0.5 * DX!r}, {HIT_N * DX!r}, {NY * DX!r}, {NZ * DX!r}}};
        Physical Volume("a") = {{1}};
        Physical Volume("b") = {{2}};
        Mesh.MeshSizeMax = {2 * DX!r};
        """))
    lammps_dir = work / "lammps"
    lammps_dir.mkdir()
    (lammps_dir / "in.hit").write_text(collision_deck())
    result = subprocess.run([LMP, "-in", "in.hit", "-log", "none"], cwd=lammps_dir, capture_output=True, text=True,
                            timeout=600)
    assert result.returncode == 0, f"lmp failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
    theirs = read_dump(lammps_dir / "dump.txt")
    yaml_path = case_dir / "hit.yaml"
    yaml_path.write_text(yaml.safe_dump(collision_case()))
    out = work / "hit"
    env = dict(os.environ, PYTHONPATH=ROOT)
    for args in ((PY, "-m", "pipeline.run", "mesh", str(yaml_path), str(case_dir / "hit.geo"), str(out / "mesh.msh")),
                 (PY, "-m", "pipeline.run", "preprocess", str(yaml_path), str(out / "mesh.msh"), str(out)),
                 (SOLVER, str(out / "case.json"), "--quiet")):
        done = subprocess.run(list(args), cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, f"{' '.join(args)} failed:\n{done.stdout}\n{done.stderr}"
    start = theirs[0][0]
    index = {tuple(np.rint(p / DX).astype(int)): i for i, p in enumerate(start)}
    ours = {}
    for k in range(HIT_STEPS // HIT_EVERY + 1):
        mesh = meshio.read(out / "frames" / f"frame_{k:06d}.vtu")
        perm = np.array([index[tuple(np.rint(p / DX).astype(int))] for p in mesh.points])
        y = np.empty_like(mesh.points)
        y[perm] = mesh.points + mesh.point_data["displacement"]
        ours[k * HIT_EVERY] = y
    return theirs, ours, start[:, 0] > b0


def test_the_contact_force_is_lammps_s_short_range_force(collision):
    theirs, ours, in_b = collision
    length = (2 * HIT_N + HIT_GAP - 1) * DX
    gap = {step: float(np.min(y[in_b, 0]) - np.max(y[~in_b, 0])) / DX for step, (y, _) in theirs.items()}
    closest = min(gap, key=gap.get)
    worst = max(float(np.max(np.abs(ours[step] - y))) / length for step, (y, _) in theirs.items())
    print(f"collision: closest gap {gap[closest]:.3f}a at step {closest}; max |Δx|/L {worst:.2e}")
    assert gap[closest] < 1.35  # the bricks came within LAMMPS's (and our) contact distance ...
    assert gap[HIT_STEPS] > gap[closest] + 0.5  # ... and bounced back
    assert worst < 1e-13  # measured 1.1e-14
