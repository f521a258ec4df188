#pragma once
// The tool under `mpirun -np R simsr ...` (a build with -DSIMSR_WITH_MPI=ON): MPI is initialized
// only when mpirun started the process (mpi::launched_by_mpirun), so a plain `simsr` never pays
// for it. With more than one rank only the commands that shard their work run (datagen
// --scenario softdeca, by sample, and face, by performance; train, each rank its block of every
// batch); any other is refused before it runs, rather than run R times
// over the same files. An error on one rank is printed with the rank and ends every rank
// (MPI_Abort: the others may be waiting for it in a collective).
#include <cstdlib>
#include <memory>
#include <string>

#if defined(SIMSR_HAVE_MPI)
#include <simsr/mpi/communicator.hpp>
#endif

namespace simsr::cli {

#if defined(SIMSR_HAVE_MPI)
/// MPI for the process when mpirun started it, else nothing.
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv) {
    if (!mpi::launched_by_mpirun()) return;
    env_ = std::make_unique<mpi::Environment>(argc, argv);
    world_ = std::make_unique<mpi::Communicator>(mpi::Communicator::world());
  }
  /// The run's ranks; nullptr when not under mpirun.
  const mpi::Communicator* world() const { return world_.get(); }
  int size() const { return world_ ? world_->size() : 1; }
  int rank() const { return world_ ? world_->rank() : 0; }
  /// Ends every rank with `code` (an error this rank printed): the others may be waiting for it.
  [[noreturn]] void abort(int code) const { world_->abort(code); }

 private:
  std::unique_ptr<mpi::Environment> env_;
  std::unique_ptr<mpi::Communicator> world_;
};
#else
/// Without MPI in the build: one process, and mpirun's R copies would each run the whole command.
class MpiSession {
 public:
  MpiSession(int&, char**&) {}
  int size() const { return 1; }
  int rank() const { return 0; }
  [[noreturn]] void abort(int code) const { std::exit(code); }
};
#endif

/// The process's session (main sets it before parsing; nullptr in tests of single commands).
inline const MpiSession*& mpi_session() {
  static const MpiSession* session = nullptr;
  return session;
}

/// True when this process prints the command's stdout: rank 0 (or no MPI).
inline bool prints_results() { return mpi_session() == nullptr || mpi_session()->rank() == 0; }

/// "" or " (rank r of R)" under mpirun with several ranks: what names a rank in messages.
inline std::string rank_suffix() {
  const MpiSession* s = mpi_session();
  if (s == nullptr || s->size() == 1) return "";
  return " (rank " + std::to_string(s->rank()) + " of " + std::to_string(s->size()) + ")";
}

/// "simsr" or "simsr (rank r of R)": the name error messages start with.
inline std::string program_name() { return "simsr" + rank_suffix(); }

}  // namespace simsr::cli
