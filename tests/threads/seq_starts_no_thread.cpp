// exec::seq starts no thread (issue #10). Each representative workload runs under exec::seq in a
// child process of its own (fork) and must leave that process with exactly one thread: libgomp
// keeps the threads of a parallel region alive afterwards, so any OpenMP region started under
// exec::seq — Eigen's own GEMM or row-major sparse × dense product, a stray pragma — is seen in
// /proc/self/status ("Threads:"). The program re-executes itself with OMP_NUM_THREADS=2 when
// OpenMP would use one thread (a region then starts none and nothing could be seen). The last
// workload runs exec::omp and must start a thread: the check itself can fail.
//
//   test_threads            # every workload; exit 1 naming each that started a thread
//   test_threads --list     # the workloads' names
//   test_threads NAME...    # only those (under gdb -ex 'set follow-fork-mode child' -ex 'break
//                           # GOMP_parallel' to see where a region starts)
//
// Needs the bunny of ../shared/data (SIMSR_DATA_DIR); without it the bunny workloads fail.
#include <simsr/data/data.hpp>
#include <simsr/eval/evaluate.hpp>
#include <simsr/interp/interp.hpp>
#include <simsr/physics/verification/cantilever.hpp>
#if SIMSR_HAVE_CHOLMOD
#include <simsr/physics/linear_solvers/cholmod_cholesky.hpp>
#endif

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#if defined(_OPENMP)
#include <omp.h>
#endif

namespace {

using namespace simsr;

/// Threads of this process now (Linux: /proc/self/status), or -1.
int thread_count() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("Threads:", 0) == 0) return std::atoi(line.c_str() + 8);
  return -1;
}

struct Bunny {
  interp::UpsamplingProblem<> problem;
  data::PairedFrames<> train, test;
};

Bunny load_bunny() {
  const std::filesystem::path dir = std::filesystem::path(SIMSR_DATA_DIR) / "bunny";
  Bunny b;
  b.problem.lr = data::read_lr_rest(dir / "lrestshape.obj");
  b.problem.hr = data::read_hr_rest(dir / "hrestshape.obj");
  const auto frames = data::read_paired_frames(dir / "train_frames.npz", b.problem.num_lr(), b.problem.num_hr());
  // 12 training frames: Ridge's frame kernel is then 12×12, its products large enough for
  // Eigen's GEMM to go parallel (the threshold is about 10⁵ multiply-adds).
  const std::vector<Index> train = {1, 2, 3, 5, 6, 7, 9, 10, 11, 13, 14, 15}, test = {0, 4};
  b.train = frames.select(train);
  b.test = frames.select(test);
  return b;
}

template <interp::Interpolator Method, class... Options>
void run_method(Bunny& b, Method& method, const Options&... options) {
  const auto r = eval::run_method(exec::seq, method, b.problem, b.train, b.test, options...);
  if (!(r.errors.statistics().mean >= 0)) throw std::runtime_error("no error statistics");
}

template <class Linear>
void cantilever(physics::BeamDiscretization d) {
  physics::CantileverOptions o;
  o.cells_through_height = 4;
  o.discretization = d;
  const auto r = physics::solve_cantilever<Linear>(exec::seq, o);
  if (!(r.tip_deflection > 0)) throw std::runtime_error("the beam did not sag");
}

#if SIMSR_HAVE_CHOLMOD
/// CHOLMOD's supernodal LLᵀ of a 7-point Laplacian on a 24³ grid (13,824 unknowns; its top
/// fronts are hundreds wide, where CHOLMOD 3's num_threads(4) loops run) under `policy`.
template <class P>
void cholmod_factor(P policy) {
  const Index m = 24, n = m * m * m;
  std::vector<Eigen::Triplet<double>> t;
  const auto id = [&](Index i, Index j, Index k) { return (i * m + j) * m + k; };
  for (Index i = 0; i < m; ++i)
    for (Index j = 0; j < m; ++j)
      for (Index k = 0; k < m; ++k) {
        t.emplace_back(int(id(i, j, k)), int(id(i, j, k)), 6.1);
        if (i + 1 < m) t.emplace_back(int(id(i, j, k)), int(id(i + 1, j, k)), -1.0), t.emplace_back(int(id(i + 1, j, k)), int(id(i, j, k)), -1.0);
        if (j + 1 < m) t.emplace_back(int(id(i, j, k)), int(id(i, j + 1, k)), -1.0), t.emplace_back(int(id(i, j + 1, k)), int(id(i, j, k)), -1.0);
        if (k + 1 < m) t.emplace_back(int(id(i, j, k)), int(id(i, j, k + 1)), -1.0), t.emplace_back(int(id(i, j, k + 1)), int(id(i, j, k)), -1.0);
      }
  physics::SparseMatrix<double> A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  physics::CholmodCholesky<> llt;
  llt.compute(policy, A);
  VecX<> x;
  if (!llt.solve(policy, VecX<>::Ones(n), x).converged) throw std::runtime_error("CHOLMOD's solve did not converge");
}
#endif

struct Workload {
  std::string name;
  std::function<void(Bunny&)> run;
  bool must_start_threads = false;  // the control
};

std::vector<Workload> workloads() {
  using namespace physics;
  const auto conforming = BeamDiscretization::conforming;
  std::vector<Workload> w = {
      {"cantilever/cholesky", [=](Bunny&) { cantilever<SparseCholesky<>>(conforming); }},
      {"cantilever/pcg-jacobi", [=](Bunny&) { cantilever<ConjugateGradient<Jacobi<>>>(conforming); }},
      {"cantilever/pcg-block-jacobi", [=](Bunny&) { cantilever<ConjugateGradient<BlockJacobi<>>>(conforming); }},
      {"cantilever/pcg-multigrid", [=](Bunny&) { cantilever<ConjugateGradient<Multigrid<>>>(conforming); }},
      {"cantilever/embedded-multigrid",
       [](Bunny&) { cantilever<ConjugateGradient<Multigrid<>>>(BeamDiscretization::embedded_bcc); }},
      {"bunny/network-neighborhoods",
       [](Bunny& b) { (void)data::compute_network_neighborhoods(exec::seq, b.problem.lr, b.problem.hr, 20, 20); }},
      {"bunny/embedded", [](Bunny& b) { interp::Embedded<> m; run_method(b, m); }},
      {"bunny/idw", [](Bunny& b) { interp::IDW<> m; run_method(b, m); }},
      {"bunny/mls", [](Bunny& b) { interp::MLS<> m; run_method(b, m); }},
      {"bunny/rbf", [](Bunny& b) { interp::RBF<> m; run_method(b, m); }},
      {"bunny/ridge", [](Bunny& b) { interp::Ridge<> m; run_method(b, m); }},
      {"bunny/beta-vae",
       [](Bunny& b) {
         interp::BetaVaeBaseline<> m;
         interp::BetaVaeTrainOptions o;
         o.epochs = 1;
         o.batch_size = 4;
         run_method(b, m, o);
       }},
      {"bunny/network",
       [](Bunny& b) {
         nn::NetworkConfig config = nn::NetworkConfig::official();
         config.residual = true;
         interp::Learned<> m(config);
         interp::NetworkTrainOptions o;
         o.trainer.epochs = 1;
         o.trainer.batch_size = 4;
         o.trainer.progress = false;
         run_method(b, m, o);
       }},
#if SIMSR_HAVE_CHOLMOD
      // CHOLMOD 3's own OpenMP loops (num_threads(4) compiled in) on this thread under exec::seq;
      // its control: under exec::omp they do start threads, so the workload reaches them
      {"cholmod/supernodal-factor", [](Bunny&) { cholmod_factor(exec::seq); }},
      {"control/cholmod-omp-starts-threads", [](Bunny&) { cholmod_factor(exec::omp); }, true},
#endif
      {"control/omp-starts-threads",
       [](Bunny&) {
         exec::set_omp_fork(exec::OmpFork::always);
         std::vector<double> x(1000);
         exec::parallel_for(exec::omp, Index(x.size()), [&](Index i) { x[std::size_t(i)] = double(i); });
       },
       true},
  };
  return w;
}

/// Runs `w` in a child process; the message of a failure, or "".
std::string run_in_child(const Workload& w, Bunny& bunny) {
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return std::string("fork failed: ") + std::strerror(errno);
  if (pid == 0) {
    int code = 0;
    try {
      w.run(bunny);
      const int threads = thread_count();
      if (w.must_start_threads ? threads < 2 : threads != 1) {
        std::printf("  %d threads after the workload\n", threads);
        code = 1;
      }
    } catch (const std::exception& e) {
      std::printf("  error: %s\n", e.what());
      code = 2;
    }
    std::fflush(nullptr);
    _exit(code);
  }
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return "waitpid failed";
  if (WIFSIGNALED(status)) return "killed by signal " + std::to_string(WTERMSIG(status));
  switch (WEXITSTATUS(status)) {
    case 0:
      return "";
    case 1:
      return w.must_start_threads ? "exec::omp started no thread: the check cannot see threads here"
                                  : "exec::seq started threads (find where: gdb -ex 'set follow-fork-mode child' -ex 'break GOMP_parallel' -ex run -ex bt --args test_threads " +
                                        w.name + ")";
    default:
      return "the workload failed";
  }
}

}  // namespace

int main(int argc, char** argv) {
#if defined(_OPENMP)
  if (omp_get_max_threads() < 2) {  // libgomp reads OMP_NUM_THREADS once, at load: start again
    if (std::getenv("SIMSR_THREADS_TEST_REEXEC")) {
      std::fprintf(stderr, "test_threads: OpenMP still uses one thread with OMP_NUM_THREADS=2\n");
      return 1;
    }
    setenv("OMP_NUM_THREADS", "2", 1);
    setenv("SIMSR_THREADS_TEST_REEXEC", "1", 1);
    execv("/proc/self/exe", argv);
    std::perror("test_threads: execv /proc/self/exe");
    return 1;
  }
#else
  std::fprintf(stderr, "test_threads: built without OpenMP: exec::seq cannot start OpenMP threads; nothing to check\n");
  return 1;
#endif
  const auto all = workloads();
  if (argc > 1 && std::strcmp(argv[1], "--list") == 0) {
    for (const auto& w : all) std::printf("%s\n", w.name.c_str());
    return 0;
  }
  std::vector<Workload> chosen;
  for (const auto& w : all) {
    bool wanted = argc < 2;
    for (int a = 1; a < argc; ++a) wanted = wanted || w.name == argv[a];
    if (wanted) chosen.push_back(w);
  }
  if (chosen.empty()) {
    std::fprintf(stderr, "test_threads: no workload of that name (--list)\n");
    return 1;
  }
  Bunny bunny;
  try {
    bunny = load_bunny();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "test_threads: the bunny (SIMSR_DATA_DIR/bunny) could not be read: %s\n", e.what());
    return 1;
  }
  if (thread_count() != 1) {
    std::fprintf(stderr, "test_threads: %d threads before any workload (reading the data started some)\n", thread_count());
    return 1;
  }
  int failures = 0;
  for (const auto& w : chosen) {
    std::printf("%s\n", w.name.c_str());
    const std::string error = run_in_child(w, bunny);
    if (!error.empty()) {
      std::printf("  FAILED: %s\n", error.c_str());
      ++failures;
    }
  }
  std::printf("%d of %zu workloads failed\n", failures, chosen.size());
  return failures == 0 ? 0 : 1;
}
