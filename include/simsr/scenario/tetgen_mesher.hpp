#pragma once
/// \file
/// A conforming tet mesh of a closed piecewise-linear domain by Debian's `tetgen` program
/// (Si 2015; `apt-get install tetgen`), the face scenario's HR mesher. The library stays
/// header-only: the program is run, not linked, and is needed only by what meshes.
///
///     scenario::TetgenOptions o{.max_volume = 0.05, .radius_edge = 1.5};
///     TetMesh<> hr = scenario::tetgen_mesh(boundary, holes, o, work_dir);
///
/// `boundary` is every facet of the domain (outer surface and inner ones, e.g. the skull) as one
/// triangle soup; `holes` are points inside the cavities to carve out (tetgen removes the tets
/// of every region reachable from a hole point without crossing a facet). The input vertices come
/// back first and in order (tetgen never moves an input vertex): vertex i of `boundary` is mesh
/// vertex i. With `preserve_boundary` (-Y) the boundary triangles are kept as they are (a surface
/// whose vertices carry data, like the skin, stays one-to-one); otherwise tetgen may split them. The program is found as $SIMSR_TETGEN, else `tetgen` on PATH.

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../io/atomic_file.hpp"
#include "../io/tetgen.hpp"
#include "../mesh/tet_mesh.hpp"
#include "../mesh/tri_mesh.hpp"

extern char** environ;

namespace simsr::scenario {

/// What tetgen is asked for.
struct TetgenOptions {
  double max_volume = 0;     ///< largest tet volume (−a), 0 = no bound
  double radius_edge = 1.5;  ///< quality bound on radius/shortest edge (−q), 0 = no refinement
  double min_dihedral = 0;   ///< with radius_edge: the smallest dihedral angle in degrees (−q r/d), 0 = tetgen's default
  bool preserve_boundary = false;  ///< -Y: no Steiner points on the boundary facets
  bool verbose = false;      ///< keep tetgen's own output on stderr as well as in the log
};

namespace detail {

inline std::string tetgen_program() {
  if (const char* p = std::getenv("SIMSR_TETGEN"); p && *p) return p;
  return "tetgen";
}

/// Runs argv[0] (searched on PATH) with stdout and stderr into `log`; returns its exit status.
/// ArgumentError when the program cannot be started.
inline int run_program(const std::vector<std::string>& args, const std::filesystem::path& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    throw ArgumentError("cannot run '" + args[0] + "': " + std::strerror(rc) + " (apt-get install tetgen, or set SIMSR_TETGEN)");
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw ArgumentError("waiting for '" + args[0] + "': " + std::strerror(errno));
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

inline std::string tail_of_file(const std::filesystem::path& p, std::size_t lines) {
  std::ifstream in(p);
  std::vector<std::string> all;
  for (std::string l; std::getline(in, l);) all.push_back(l);
  std::string out;
  for (std::size_t i = all.size() > lines ? all.size() - lines : 0; i < all.size(); ++i) out += all[i] + "\n";
  return out;
}

}  // namespace detail

/// Meshes the domain bounded by `boundary` (closed, non-self-intersecting facets) minus the
/// cavities holding `holes`, in `work_dir` (created; the PLC, tetgen's output and its log stay
/// there to look at). Errors: ArgumentError for bad input or a missing program; Error with the
/// end of tetgen's log when tetgen fails (self-intersecting facets, say) or its output does not
/// keep the input vertices.
inline TetMesh<> tetgen_mesh(const TriMesh<>& boundary, const std::vector<Vec3<>>& holes, const TetgenOptions& opt,
                             const std::filesystem::path& work_dir) {
  if (boundary.F.rows() == 0) throw ArgumentError("tetgen_mesh: no boundary facets");
  if (!boundary.V.allFinite()) throw ArgumentError("tetgen_mesh: non-finite boundary vertices");
  if (opt.max_volume < 0 || opt.radius_edge < 0 || opt.min_dihedral < 0)
    throw ArgumentError("tetgen_mesh: max_volume, radius_edge and min_dihedral must be ≥ 0");
  std::filesystem::create_directories(work_dir);
  const auto smesh = work_dir / "domain.smesh";
  std::ostringstream s;
  s.precision(17);
  s << "# simsr::scenario::tetgen_mesh: " << boundary.V.rows() << " nodes, " << boundary.F.rows() << " facets, " << holes.size() << " holes\n";
  s << boundary.V.rows() << " 3 0 0\n";
  for (Index v = 0; v < boundary.V.rows(); ++v) s << v << ' ' << boundary.V(v, 0) << ' ' << boundary.V(v, 1) << ' ' << boundary.V(v, 2) << '\n';
  s << boundary.F.rows() << " 0\n";
  for (Index f = 0; f < boundary.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c)
      if (boundary.F(f, c) < 0 || boundary.F(f, c) >= boundary.V.rows())
        throw ArgumentError("tetgen_mesh: facet " + std::to_string(f) + " has corner " + std::to_string(boundary.F(f, c)) + " outside the vertices");
    s << "3 " << boundary.F(f, 0) << ' ' << boundary.F(f, 1) << ' ' << boundary.F(f, 2) << '\n';
  }
  s << holes.size() << '\n';
  for (std::size_t h = 0; h < holes.size(); ++h) s << h << ' ' << holes[h].x() << ' ' << holes[h].y() << ' ' << holes[h].z() << '\n';
  s << "0\n";
  io::write_file_atomic(smesh, s.str());

  std::ostringstream sw;
  sw.precision(12);
  sw << "-pzQ";  // PLC, zero-based, quiet
  if (opt.radius_edge > 0) {
    sw << 'q' << opt.radius_edge;
    if (opt.min_dihedral > 0) sw << '/' << opt.min_dihedral;
  }
  if (opt.max_volume > 0) sw << 'a' << opt.max_volume;
  if (opt.preserve_boundary) sw << 'Y';
  const auto log = work_dir / "tetgen.log";
  for (const char* old : {"domain.1.node", "domain.1.ele", "domain.1.face", "domain.1.edge"})
    std::filesystem::remove(work_dir / old);  // never read a previous run's output
  const int rc = detail::run_program({detail::tetgen_program(), sw.str(), smesh.string()}, log);
  if (rc != 0)
    throw Error("tetgen " + sw.str() + " " + smesh.string() + " failed (exit " + std::to_string(rc) + "); the end of " + log.string() +
                ":\n" + detail::tail_of_file(log, 15));
  const auto ele = work_dir / "domain.1.ele";
  if (!std::filesystem::exists(ele)) throw Error("tetgen wrote no " + ele.string() + " (see " + log.string() + ")");
  const auto m = io::read_tetgen<Scalar>(ele);
  // tetgen prints coordinates with 16 significant digits: the input comes back to ~1e-15 relative
  const double scale = std::max(1.0, boundary.V.cwiseAbs().maxCoeff());
  if (m.V.rows() < boundary.V.rows() || !((m.V.topRows(boundary.V.rows()) - boundary.V).cwiseAbs().maxCoeff() <= 1e-12 * scale))
    throw Error("tetgen_mesh: tetgen's nodes do not begin with the input vertices (" + ele.string() + ")");
  TetMesh<> out = m.tet_mesh();
  out.V.topRows(boundary.V.rows()) = boundary.V;  // exactly the input, not its printed digits
  return out;
}

}  // namespace simsr::scenario
