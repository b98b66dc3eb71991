"""End to end: LAMMPS's breaking rules and the surface correction on 1, 2 and 3 MPI ranks (issue 15).

On the coarse cracking plate of test_mpi_ranks.py (1234 nodes, 300 steps), each of
- `breaking_order: lammps` (a bond carries its force in the pass it breaks; before, the pieces were
  built without the order and ran the thesis order: a silently different run),
- `critical_stretch_alpha: 0.25` with the LAMMPS order (s0_i = s00 − α·min_j s_ij: a bond's threshold
  min(s0_i, s0_j) reads the s0 of its ghost end, refreshed from its owner before each breaking pass),
- `surface_correction: energy` and `volume` (the factors computed on the whole model before the
  decomposition)
writes on 2 and 3 ranks (and on 1 for α) frames, frames.pvd and history.csv
byte for byte as the serial run. A checkpoint of the α run holds the owners' s0 in global node
order: written on 2 ranks it continues on 3 and on 1, written serially it continues on 2, each
byte for byte as the uninterrupted serial run.
"""
import re
import shutil

import pytest

# prepared: the coarse plate, meshed and preprocessed once per module; pytestmark: skip without MPI.
from test_mpi_checkpoint import assert_same_run, restart, restarted_at_step, with_checkpoints
from test_mpi_ranks import copy_case, history_without_wall_time, prepared, pytestmark, solve  # noqa: F401, F811


def lammps_order(case):
    case["breaking_order"] = "lammps"


def alpha_rule(case):
    case["breaking_order"] = "lammps"
    for block in case["blocks"]:
        block["critical_stretch_alpha"] = 0.25


def surface_corrected(case):
    case["surface_correction"] = "energy"


def volume_corrected(case):
    case["surface_correction"] = "volume"


VARIANTS = {"lammps": (lammps_order, (2, 3)), "alpha": (alpha_rule, (1, 2, 3)),
            "surface": (surface_corrected, (2, 3)), "volume": (volume_corrected, (2, 3))}


def broken_bonds(folder):
    history = history_without_wall_time(folder)
    return int(history[-1].split(",")[history[0].split(",").index("broken_bonds")])


@pytest.fixture(scope="module")
def thesis_serial(prepared):
    folder = copy_case(prepared, "thesis_serial")
    result = solve(folder, None)
    assert result.returncode == 0, result.stderr
    return folder


@pytest.mark.parametrize("kind", sorted(VARIANTS))
def test_decomposed_runs_equal_the_serial_run_byte_for_byte(prepared, thesis_serial, kind):
    change, rank_counts = VARIANTS[kind]
    serial = copy_case(prepared, f"{kind}_serial", change)
    result = solve(serial, None)
    assert result.returncode == 0, result.stderr
    assert broken_bonds(serial) > 100  # the plate cracked: bonds broke across the pieces' borders too
    # The option changes the run: a piece that ignored it would differ from the serial run below.
    assert history_without_wall_time(serial) != history_without_wall_time(thesis_serial)
    serial_log = (serial / "run.log").read_text()
    for ranks in rank_counts:
        folder = copy_case(prepared, f"{kind}_np{ranks}", change)
        result = solve(folder, ranks)
        assert result.returncode == 0, f"{kind} np{ranks}: {result.stderr}"
        assert_same_run(serial, folder)
        if kind in ("surface", "volume"):  # run.log's factor range: over every rank's rows, as the serial run's
            method = "energy" if kind == "surface" else "volume"
            factors = re.search(rf"work: surface correction {method} .*", serial_log).group(0)
            assert "factors g from" in factors
            assert factors in (folder / "run.log").read_text()


def test_an_alpha_checkpoint_continues_on_any_rank_count_bitwise(prepared):
    def change(case):
        alpha_rule(case)
        with_checkpoints(3.0e-4, 1.2e-4)(case)
    reference = copy_case(prepared, "alpha_ckpt_reference", change)
    assert solve(reference, None).returncode == 0
    written = {}
    for name, ranks in (("np2", 2), ("serial", None)):
        written[name] = copy_case(prepared, f"alpha_ckpt_{name}", change)
        result = solve(written[name], ranks)
        assert result.returncode == 0, result.stderr
        assert (written[name] / "checkpoint.bin").exists()
    for source, ranks in (("np2", 3), ("np2", None), ("serial", 2)):
        folder = prepared[0] / f"alpha_ckpt_{source}_to_{ranks or 'serial'}"
        shutil.copytree(written[source], folder)
        result = restart(folder, ranks)
        assert result.returncode == 0, f"{source} → {ranks}: {result.stderr}"
        assert restarted_at_step(folder) > 200  # from the last periodic checkpoint, not from the start
        assert_same_run(reference, folder)
