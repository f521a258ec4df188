#pragma once
/// \file
/// simsr::mpi (optional: `-DSIMSR_WITH_MPI=ON`, target `simsr::mpi`, Debian's OpenMPI): a small
/// communicator over MPI's C API with the few collectives the sharded datagen and the
/// data-parallel trainer use. Every MPI call's return code is checked (the communicator's error
/// handler is MPI_ERRORS_RETURN) and a failure is an `mpi::MpiError` naming the call and MPI's
/// own message. An exception on one rank cannot be rethrown on the others, which may be waiting
/// in a collective: `run_or_abort` prints the failing rank's message and aborts every rank
/// (MPI_Abort), so a run ends cleanly instead of hanging; files are written atomically, so what a
/// killed rank leaves is its finished parts, which a rerun resumes.
///
///     int main(int argc, char** argv) {
///       simsr::mpi::Environment env(argc, argv);
///       return simsr::mpi::run_or_abort(simsr::mpi::Communicator::world(), [&](const auto& comm) {
///         auto all = comm.allgather(comm.rank());       // {0, 1, ..., size-1} on every rank
///         return 0;
///       });
///     }

#include <mpi.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../core/work_shard.hpp"

namespace simsr::mpi {

/// An MPI call failed: `call()` is its name, `code()` MPI's error code.
class MpiError : public Error {
 public:
  MpiError(std::string call, int code) : Error(format(call, code)), call_(std::move(call)), code_(code) {}
  const std::string& call() const noexcept { return call_; }
  int code() const noexcept { return code_; }

 private:
  static std::string format(const std::string& call, int code) {
    char text[MPI_MAX_ERROR_STRING];
    int length = 0;
    if (MPI_Error_string(code, text, &length) != MPI_SUCCESS) length = 0;
    return "mpi: " + call + " failed (error " + std::to_string(code) + (length > 0 ? ": " + std::string(text, std::size_t(length)) : "") + ")";
  }
  std::string call_;
  int code_;
};

namespace detail {
inline void check(int code, const char* call) {
  if (code != MPI_SUCCESS) throw MpiError(call, code);
}
}  // namespace detail

/// True when this process was started by mpirun/mpiexec (OpenMPI's or a PMIx launcher's
/// environment): the tool initializes MPI only then, so a plain `simsr datagen` never pays for it.
inline bool launched_by_mpirun() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"})
    if (std::getenv(v) != nullptr) return true;
  return false;
}

/// MPI_Init_thread / MPI_Finalize for the process (one per process, on its main thread).
/// MPI_THREAD_FUNNELED: ranks run OpenMP inside, MPI is called from the main thread only.
class Environment {
 public:
  Environment(int& argc, char**& argv) {
    int initialized = 0;
    detail::check(MPI_Initialized(&initialized), "MPI_Initialized");
    if (initialized) throw ArgumentError("mpi::Environment: MPI is initialized already (one Environment per process)");
    int provided = 0;
    detail::check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
    if (provided < MPI_THREAD_FUNNELED) {
      MPI_Finalize();
      throw ArgumentError("mpi::Environment: this MPI gives thread level " + std::to_string(provided) + ", simsr needs MPI_THREAD_FUNNELED");
    }
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  }
  Environment(const Environment&) = delete;
  Environment& operator=(const Environment&) = delete;
  ~Environment() {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
  }
};

/// A communicator (not owned: MPI_COMM_WORLD or one the caller keeps alive) with its rank and
/// size, and the collectives simsr uses. Every collective must be called by every rank in the
/// same order, as MPI requires.
class Communicator {
 public:
  explicit Communicator(MPI_Comm comm) : comm_(comm) {
    detail::check(MPI_Comm_rank(comm_, &rank_), "MPI_Comm_rank");
    detail::check(MPI_Comm_size(comm_, &size_), "MPI_Comm_size");
    detail::check(MPI_Comm_set_errhandler(comm_, MPI_ERRORS_RETURN), "MPI_Comm_set_errhandler");
  }
  /// All processes of the run.
  static Communicator world() { return Communicator(MPI_COMM_WORLD); }
  /// This process alone (a single-process run inside an MPI program).
  static Communicator self() { return Communicator(MPI_COMM_SELF); }

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == 0; }
  MPI_Comm native() const { return comm_; }
  /// This rank's share of a run split over the ranks.
  WorkShard shard() const { return {rank_, size_}; }

  void barrier() const { detail::check(MPI_Barrier(comm_), "MPI_Barrier"); }

  /// Every rank's `value`, in rank order, on every rank (a trivially copyable T).
  template <class T>
  std::vector<T> allgather(const T& value) const {
    static_assert(std::is_trivially_copyable_v<T>, "mpi::Communicator::allgather: T must be trivially copyable (sent as bytes)");
    std::vector<T> out(static_cast<std::size_t>(size_));
    detail::check(MPI_Allgather(&value, int(sizeof(T)), MPI_BYTE, out.data(), int(sizeof(T)), MPI_BYTE, comm_), "MPI_Allgather");
    return out;
  }

  /// Every rank's array (any length each), in rank order, on every rank.
  template <class T>
  std::vector<std::vector<T>> allgather(const std::vector<T>& values) const {
    static_assert(std::is_trivially_copyable_v<T>, "mpi::Communicator::allgather: T must be trivially copyable (sent as bytes)");
    const std::int64_t bytes = std::int64_t(values.size() * sizeof(T));
    const std::vector<std::int64_t> sizes = allgather(bytes);
    const std::vector<std::size_t> counts(sizes.begin(), sizes.end());
    std::size_t total = 0;
    for (std::size_t c : counts) total += c;
    std::vector<unsigned char> buffer(total);
    allgather_bytes(values.data(), counts, buffer.data());
    std::vector<std::vector<T>> out(sizes.size());
    std::size_t at = 0;
    for (std::size_t r = 0; r < sizes.size(); ++r) {
      out[r].resize(counts[r] / sizeof(T));
      if (counts[r] > 0) std::memcpy(out[r].data(), buffer.data() + at, counts[r]);
      at += counts[r];
    }
    return out;
  }

  /// `all` ← every rank's bytes[r] bytes, concatenated in rank order (`mine`: bytes[rank()] of
  /// them); every rank passes the same `bytes`. One MPI_Allgatherv: ArgumentError beyond what
  /// its int counts hold.
  void allgather_bytes(const void* mine, const std::vector<std::size_t>& bytes, void* all) const {
    if (bytes.size() != std::size_t(size_))
      throw ArgumentError("mpi::Communicator::allgather_bytes: " + std::to_string(bytes.size()) + " byte counts for " + std::to_string(size_) + " ranks");
    std::vector<int> counts(bytes.size()), displs(bytes.size());
    std::size_t total = 0;
    for (std::size_t r = 0; r < bytes.size(); ++r) {
      if (total + bytes[r] > std::size_t(std::numeric_limits<int>::max()))
        throw ArgumentError("mpi::Communicator::allgather: " + std::to_string(total + bytes[r]) + " bytes in all, more than one MPI call sends");
      counts[r] = int(bytes[r]);
      displs[r] = int(total);
      total += bytes[r];
    }
    detail::check(MPI_Allgatherv(mine, counts[std::size_t(rank_)], MPI_BYTE, all, counts.data(), displs.data(), MPI_BYTE, comm_), "MPI_Allgatherv");
  }

  /// Every rank's string, in rank order, on every rank.
  std::vector<std::string> allgather(const std::string& s) const {
    const auto parts = allgather(std::vector<char>(s.begin(), s.end()));
    std::vector<std::string> out;
    for (const auto& p : parts) out.emplace_back(p.begin(), p.end());
    return out;
  }

  /// `value` of rank `root` on every rank.
  std::string broadcast(const std::string& value, int root = 0) const {
    check_root(root, "broadcast");
    std::int64_t n = std::int64_t(value.size());
    detail::check(MPI_Bcast(&n, 1, MPI_INT64_T, root, comm_), "MPI_Bcast");
    std::string out = rank_ == root ? value : std::string(std::size_t(n), '\0');
    if (n > std::int64_t(std::numeric_limits<int>::max())) throw ArgumentError("mpi::Communicator::broadcast: " + std::to_string(n) + " bytes");
    if (n > 0) detail::check(MPI_Bcast(out.data(), int(n), MPI_CHAR, root, comm_), "MPI_Bcast");
    return out;
  }

  template <class T>
  T broadcast(const T& value, int root = 0) const {
    static_assert(std::is_trivially_copyable_v<T>, "mpi::Communicator::broadcast: T must be trivially copyable (sent as bytes)");
    check_root(root, "broadcast");
    T out = value;
    detail::check(MPI_Bcast(&out, int(sizeof(T)), MPI_BYTE, root, comm_), "MPI_Bcast");
    return out;
  }

  /// True on every rank when `flag` is true on any (a logical or: exact, in any order).
  bool any(bool flag) const {
    int in = flag ? 1 : 0, out = 0;
    detail::check(MPI_Allreduce(&in, &out, 1, MPI_INT, MPI_LOR, comm_), "MPI_Allreduce");
    return out != 0;
  }

  /// Ends every rank of the run now (MPI_Abort): for an error a rank cannot share.
  [[noreturn]] void abort(int code) const {
    MPI_Abort(comm_, code);
    std::_Exit(code);  // MPI_Abort does not return; the compiler is told so
  }

 private:
  void check_root(int root, const char* what) const {
    if (root < 0 || root >= size_)
      throw ArgumentError(std::string("mpi::Communicator::") + what + ": root " + std::to_string(root) + " of " + std::to_string(size_) + " ranks");
  }
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
};

/// The pattern of a sharded run's end: every rank's `part` (its share's summary) gathered in rank
/// order, `finish(parts)` run on rank 0 alone (it assembles the whole run's files and returns the
/// summary), and rank 0's summary returned on every rank. The gather is also the point where
/// every rank's files are written.
template <class Finish>
std::string finish_on_root(const Communicator& comm, const std::string& part, Finish&& finish) {
  const std::vector<std::string> parts = comm.allgather(part);
  std::string summary;
  if (comm.is_root()) summary = finish(parts);
  return comm.broadcast(summary, 0);
}

/// Runs `f(comm)` on this rank and returns its result; an exception ends the whole run: "simsr:
/// rank R of S: <message>" on stderr, then MPI_Abort with exit code `code` (the other ranks may be
/// waiting in a collective and could not be told otherwise).
template <class F>
int run_or_abort(const Communicator& comm, F&& f, int code = 1) {
  try {
    return f(comm);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "simsr: rank %d of %d: %s\n", comm.rank(), comm.size(), e.what());
  } catch (...) {
    std::fprintf(stderr, "simsr: rank %d of %d: an exception that is not a std::exception\n", comm.rank(), comm.size());
  }
  std::fflush(stderr);
  comm.abort(code);
}

}  // namespace simsr::mpi
