// cantilever: the Euler–Bernoulli verification of the quasistatic solver (issue #5). A beam
// clamped at x = 0 sags under its own weight; prints one JSON line
//   {"tip_deflection":…, "euler_bernoulli":…, "relative_error":…, …}
//
//   cantilever                               # conforming mesh, 4 cells through the height
//   cantilever --cells 10                    # 60,000 tets: within 3 % of beam theory
//   cantilever --embedded --cells 6          # the BCC embedded lattice of the same beam
//   cantilever --solver pcg-block-jacobi --omp --progress
//   cantilever --cells 8 --vtu beam.vtu      # the deformed beam for ParaView (displacement, volume ratio)
#include <simsr/io/vtu.hpp>
#include <simsr/mesh/volume.hpp>
#include <simsr/physics/verification/cantilever.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <map>
#include <string>

#include "../simsr/errors.hpp"

namespace {

using namespace simsr;
using namespace simsr::physics;

template <class Policy>
CantileverResult solve_with(Policy policy, const std::string& solver, const CantileverOptions& o) {
  if (solver == "cholesky") return solve_cantilever<SparseCholesky<>>(policy, o);
  if (solver == "pcg-jacobi") return solve_cantilever<ConjugateGradient<Jacobi<>>>(policy, o);
  if (solver == "pcg-multigrid") return solve_cantilever<ConjugateGradient<Multigrid<>>>(policy, o);
  return solve_cantilever<ConjugateGradient<BlockJacobi<>>>(policy, o);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Cantilever under gravity vs Euler–Bernoulli: one JSON line on stdout"};
  CantileverOptions o;
  bool embedded = false, omp = false, progress = false;
  std::string solver = "cholesky", vtu;
  app.add_option("--cells", o.cells_through_height, "cells through the beam height (resolution h = height / cells)")
      ->capture_default_str()->check(CLI::PositiveNumber);
  app.add_flag("--embedded", embedded, "BCC embedded lattice instead of the conforming box mesh");
  app.add_option("--solver", solver, "linear solver")->capture_default_str()
      ->check(CLI::IsMember({"cholesky", "pcg-jacobi", "pcg-block-jacobi", "pcg-multigrid"}));
  app.add_flag("--omp", omp, "assemble (and run PCG) with OpenMP threads");
  app.add_flag("--progress", progress, "print each Newton iteration on stderr");
  app.add_option("--vtu", vtu, "write the deformed beam (point data: displacement; cell data: volume ratio J) for ParaView");
  app.add_option("--length", o.length, "beam length L along x (m)")->capture_default_str();
  app.add_option("--width", o.width, "beam width W along y (m)")->capture_default_str();
  app.add_option("--height", o.height, "beam height H along z (m)")->capture_default_str();
  app.add_option("--young", o.young, "Young's modulus E (Pa)")->capture_default_str();
  app.add_option("--poisson", o.poisson, "Poisson's ratio ν (beam theory assumes 0)")->capture_default_str();
  app.add_option("--density", o.density, "density ρ (kg/m³)")->capture_default_str();
  app.add_option("--gravity", o.gravity, "gravity g (m/s²)")->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : simsr::cli::exit_usage;
  }
  return simsr::cli::run_guarded(
      [&] {
        o.discretization = embedded ? BeamDiscretization::embedded_bcc : BeamDiscretization::conforming;
        if (progress)
          o.newton.progress = [](const NewtonIteration& it) {
            std::fprintf(stderr, "newton %ld: energy %.9e J, |gradient| %.3e N, step %g%s, %ld linear iterations\n", long(it.iteration),
                         it.energy, it.gradient_norm, it.step_length, it.projected ? " (projected Hessian)" : "", long(it.linear_iterations));
          };
        const CantileverResult r = omp ? solve_with(exec::omp, solver, o) : solve_with(exec::seq, solver, o);
        const nlohmann::ordered_json j = {{"tip_deflection", r.tip_deflection},
                                          {"euler_bernoulli", r.euler_bernoulli},
                                          {"relative_error", r.relative_error},
                                          {"discretization", embedded ? "embedded_bcc" : "conforming"},
                                          {"cells_through_height", o.cells_through_height},
                                          {"vertices", r.vertices},
                                          {"tets", r.tets},
                                          {"newton_iterations", r.newton_iterations},
                                          {"solver", solver},
                                          {"seconds", r.seconds}};
        if (!vtu.empty()) {
          const Points<> u = r.positions - r.mesh.V;
          const VecX<> J = signed_volumes(exec::seq, r.positions, r.mesh.T).cwiseQuotient(signed_volumes(exec::seq, r.mesh.V, r.mesh.T));
          io::VtuGrid grid;
          grid.set_points(r.positions).set_tets(r.mesh.T).add_point_data("displacement", u).add_cell_data("volume_ratio", J);
          io::write_vtu(vtu, grid);
        }
        std::cout << j.dump() << std::endl;
        return 0;
      },
      "cantilever");
}
