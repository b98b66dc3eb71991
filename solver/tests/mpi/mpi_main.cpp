// main() of pd_mpi_tests, run under mpiexec with 1, 2 and 3 ranks (CMakeLists.txt): MPI around
// GoogleTest, and a failure on any rank fails the run on every rank.
#include <gtest/gtest.h>
#include <mpi.h>

#include "parallel/session.hpp"

int main(int argc, char** argv) {
  int provided = 0;  // always under mpiexec (CMakeLists.txt), so MPI directly, not parallel/session
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  ::testing::InitGoogleTest(&argc, argv);
  // One full report, from rank 0; the other ranks print their failures only.
  if (pd::world_ranks().rank != 0) ::testing::GTEST_FLAG(brief) = true;
  const int mine = RUN_ALL_TESTS();
  int worst = 0;
  MPI_Allreduce(&mine, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return worst;
}
