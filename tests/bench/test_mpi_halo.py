"""pd_mpi_halo (bench/mpi_ranks.py's rows, issue 15) counts what a decomposed Verlet step sends.

On a 12³ brick (δ = 3.0002 dx) two Morton pieces of equal bond work are the halves z < 6 dx and
z ≥ 6 dx, 864 nodes each; each needs the 3 layers of 12² nodes beyond its face as ghosts. So per
step each rank sends: one halo message of 432 ghosts × 3 doubles = 10 368 bytes, and 2 reductions
(MPI_Allreduce), whatever the piece's size: the breaking pass's count of broken bonds with the
exact sum of the energy they held (one accumulator of 70 int64 — core/exact_sum.hpp: 67 digit
limbs and 3 counts of ±∞ and NaN — and one int64: 568 bytes), and the kinetic and strain energy of
the blow-up watch (two accumulators: 1120 bytes). Each reduction is a point where every rank waits
for the slowest, so a step has as few as the results allow.
"""
import os
import shutil

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXE = os.path.join(ROOT, "build", "solver", "pd_mpi_halo")
MPI_ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")

pytestmark = pytest.mark.skipif(not os.path.exists(EXE) or shutil.which("mpiexec") is None,
                                reason="pd_mpi_halo not built (PD_MPI off) or no mpiexec")


def test_two_ranks_send_one_message_of_their_face_layers_and_two_reductions_per_step():
    from bench.mpi_ranks import run_ours
    rows = run_ours(EXE, 12, 3, 2, 1)
    assert [r["rank"] for r in rows] == ["0", "1"]
    for r in rows:
        assert int(r["nodes"]) == 12 ** 3
        assert int(r["owned"]) == 864 and int(r["ghosts"]) == 432
        assert float(r["ghosts_per_owned"]) == 0.5
        assert float(r["halo_messages_per_step"]) == 1.0
        assert int(r["halo_bytes_per_step"]) == 432 * 3 * 8
        assert float(r["reductions_per_step"]) == 2.0
        assert int(r["reduction_bytes_per_step"]) == 8 * (70 + 1) + 2 * 8 * 70
        assert float(r["peak_rss_mb"]) > 0.0


@pytest.mark.parametrize("extra, messages", [(("--alpha", "0.25"), 1), (("--law", "lps"), 2)])
def test_lammps_s0_travels_with_u_in_one_message_and_lps_sends_p_in_a_second(extra, messages):
    """LAMMPS's α rule reads the s0 of a bond's ghost end: it travels with u, 4 doubles per ghost in
    one message per step (432 × 4 × 8 bytes), not in a second message. LPS's force sweep needs P of
    the ghosts, known only after the first sweep: a second message of 1 double per ghost. Either way
    432 × 4 × 8 bytes a step, and with --blocking (every row a boundary row: no overlap) the same."""
    from bench.mpi_ranks import run_ours
    for blocking in ((), ("--blocking",)):
        for r in run_ours(EXE, 12, 3, 2, 1, extra + blocking):
            assert float(r["halo_messages_per_step"]) == messages
            assert int(r["halo_bytes_per_step"]) == 432 * 4 * 8
            assert float(r["reductions_per_step"]) == 2.0


def test_the_bond_count_of_a_run_whose_ranks_build_only_their_rows_is_the_serial_one():
    """On 2 ranks each builds only its own rows (the whole list is only counted): the directed bonds
    the row reports, and so its bond updates per second, are still the whole brick's."""
    from bench.mpi_ranks import run_ours
    (serial,) = run_ours(EXE, 12, 3, 1, 1)
    assert int(serial["directed_bonds"]) > 100 * 12 ** 3 // 2
    for r in run_ours(EXE, 12, 3, 2, 1):
        assert r["directed_bonds"] == serial["directed_bonds"]
        assert float(r["bond_updates_per_s"]) > 0.0


def test_one_rank_takes_the_serial_path_and_sends_nothing():
    from bench.mpi_ranks import run_ours
    (r,) = run_ours(EXE, 12, 3, 1, 1)
    assert int(r["owned"]) == 12 ** 3 and int(r["ghosts"]) == 0
    assert int(r["halo_bytes_per_step"]) == 0 and int(r["reduction_bytes_per_step"]) == 0
