// simsr: the command-line tool of the simsr library. Each subcommand lives in cmd_<name>.hpp.
//   simsr info FILE            one JSON object describing a mesh or array file
//   simsr convert IN OUT       convert between mesh formats by extension
//   simsr knn ...              Euclidean kNN (KD-tree), .npy in, .npz out
//   simsr neighbors ...        §3.2 upsampling neighbourhoods + LR geodesic graph
//   simsr upsample ...         LR frames → HR frames with a baseline interpolator
//   simsr baselines ...        every baseline on held-out frames: statistics, plots, heatmaps
//   simsr eval ...             error statistics of predicted HR frames against the truth
//   simsr train ...            train the super-resolution network → one model .npz
//   simsr infer ...            run a trained network on LR frames
//   simsr datagen ...          simulate paired LR/HR data (the face)
//   simsr demo ...             the paper's evaluation end to end (cmd_demo.cpp)
//   simsr ablate ...           the §5.4 ablations: Table 2 and Fig. 9 (cmd_demo.cpp)
//   simsr animate ...          the face simulated and super-resolved live, frame rates (cmd_animate.cpp)
// Errors: a message on stderr naming the file, and an exit code in 1..125 (errors.hpp).
#include "cmd_baselines.hpp"
#include "cmd_convert.hpp"
#include "cmd_datagen.hpp"
#include "cmd_eval.hpp"
#include "cmd_info.hpp"
#include "cmd_infer.hpp"
#include "cmd_knn.hpp"
#include "cmd_neighbors.hpp"
#include "cmd_surrogate.hpp"
#include "cmd_train.hpp"
#include "cmd_upsample.hpp"
#include "commands.hpp"
#include "errors.hpp"
#include "mpi_session.hpp"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>

int main(int argc, char** argv) {
  // stdout carries one JSON document or a command's final tables. Fully buffered (also on a
  // terminal or under `stdbuf -oL`), a failed write shows at the flush below with its errno; line
  // buffered, it failed at a newline and its errno was gone by then ("write failed", no reason).
  std::setvbuf(stdout, nullptr, _IOFBF, std::size_t(1) << 16);
  const simsr::cli::MpiSession mpi(argc, argv);  // MPI under mpirun (a build with SIMSR_WITH_MPI), else nothing
  simsr::cli::mpi_session() = &mpi;
  CLI::App app{"simsr: physics-based simulation super-resolution tools"};
  app.require_subcommand(1);
  std::function<int()> action;
  simsr::cli::add_info(app, action);
  simsr::cli::add_convert(app, action);
  simsr::cli::add_knn(app, action);
  simsr::cli::add_neighbors(app, action);
  simsr::cli::add_upsample(app, action);
  simsr::cli::add_baselines(app, action);
  simsr::cli::add_eval(app, action);
  simsr::cli::add_train(app, action);
  simsr::cli::add_infer(app, action);
  simsr::cli::add_datagen(app, action);
  simsr::cli::add_train_surrogate(app, action);
  simsr::cli::add_demo(app, action);
  simsr::cli::add_ablate(app, action);
  simsr::cli::add_animate(app, action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : simsr::cli::exit_usage;
  }
  if (mpi.size() > 1) {
    const std::string name = app.get_subcommands().front()->get_name();
    if (name != "datagen" && name != "train") {  // datagen checks its scenario itself
      std::fprintf(stderr, "%s: invalid argument: simsr %s runs on one process; under mpirun -np %d only datagen (--scenario softdeca, face) and train share their work\n",
                   simsr::cli::program_name().c_str(), name.c_str(), mpi.size());
      return simsr::cli::exit_argument;  // every rank refuses alike: no rank waits for another
    }
  }
  const int code = simsr::cli::run_guarded(action, simsr::cli::program_name().c_str());
  if (code != 0 && mpi.size() > 1) {
    std::fflush(stdout);
    std::fflush(stderr);
    mpi.abort(code);  // the other ranks may wait for this one in a collective
  }
  // The JSON goes to stdout: a failed write there (a full disk, /dev/full) is an error too.
  errno = 0;
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    std::fprintf(stderr, "simsr: error: <stdout>: write failed%s%s\n", errno ? ": " : "", errno ? std::strerror(errno) : "");
    return code != 0 ? code : simsr::cli::exit_parse;
  }
  return code;
}
