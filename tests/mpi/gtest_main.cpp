// main() of the MPI gtest binaries (tests/mpi/tests.cmake): MPI (and Zoltan) started for every test,
// one report, rank 0's; a failure on another rank still fails mpirun's exit status.
#include <gtest/gtest.h>

#include "hilldem/parallel/mpi_world.hpp"

int main(int argc, char** argv) {
  hilldem::parallel::MpiSession mpi(argc, argv);
  ::testing::InitGoogleTest(&argc, argv);
  if (mpi.rank() != 0) {
    ::testing::TestEventListeners& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  return RUN_ALL_TESTS();
}
