// run_or_abort ends every rank when one throws (mpirun -np 2 abort_check): rank 1 throws while
// rank 0 waits in a barrier it would otherwise wait in forever. ctest passes the test when the
// output holds rank 1's message (and mpirun's exit is not 0: rank 0 never prints "not aborted").
#include <simsr/mpi/communicator.hpp>

#include <cstdio>

int main(int argc, char** argv) {
  simsr::mpi::Environment env(argc, argv);
  return simsr::mpi::run_or_abort(simsr::mpi::Communicator::world(), [](const simsr::mpi::Communicator& comm) {
    if (comm.rank() == 1) throw simsr::ArgumentError("the test's error on rank 1");
    comm.barrier();  // rank 1 never arrives
    std::printf("not aborted\n");
    return 0;
  });
}
