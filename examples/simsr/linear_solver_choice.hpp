#pragma once
// `--linear-solver simplicial|cholmod` (datagen's softdeca, sheet and disk; demo's sheet and disk):
// the physics::LinearSolver type a name stands for, handed to a generic callable as a tag, so a
// command instantiates what it runs with either solver and the choice stays one option.
#include <simsr/core/error.hpp>
#include <simsr/physics/linear_solvers/linear_solvers.hpp>
#if defined(SIMSR_HAVE_CHOLMOD)
#include <simsr/physics/linear_solvers/cholmod_cholesky.hpp>
#endif

#include <string>

namespace simsr::cli {

template <class L>
struct LinearSolverTag {};

/// f(LinearSolverTag<L>{}) with L the solver `name` names; ArgumentError for another name, or for
/// cholmod in a build without CHOLMOD.
template <class F>
decltype(auto) with_linear_solver(const std::string& name, F&& f) {
  if (name == "simplicial") return f(LinearSolverTag<physics::SparseCholesky<>>{});
  if (name != "cholmod") throw ArgumentError("--linear-solver: simplicial or cholmod (got '" + name + "')");
#if defined(SIMSR_HAVE_CHOLMOD)
  return f(LinearSolverTag<physics::CholmodCholesky<>>{});
#else
  throw ArgumentError("--linear-solver cholmod: this simsr was built without CHOLMOD (configure with -DSIMSR_WITH_CHOLMOD=ON)");
#endif
}

}  // namespace simsr::cli
