// The MPI suite's main: MPI initialized around doctest, every rank running every case (each case
// that needs several ranks says so), and the run failed on every rank when a check failed on any.
// Run as `mpirun -np 2 test_mpi`; rank 0 reports in full, the others print failures only.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <simsr/mpi/communicator.hpp>

int main(int argc, char** argv) {
  simsr::mpi::Environment env(argc, argv);
  const auto world = simsr::mpi::Communicator::world();
  doctest::Context context(argc, argv);
  if (!world.is_root()) context.setOption("minimal", true);
  const int status = context.run();
  const bool failed = world.any(status != 0);
  if (context.shouldExit()) return status;
  return failed ? 1 : 0;
}
