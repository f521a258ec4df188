#pragma once
/// \file
/// What every solver over a sum of EnergyTerms does the same way (the Newton solver and the
/// local–global solver): set the Dirichlet vertices, sum the terms' energies, and sum their
/// gradients over the free DOFs together with the size of the forces in balance (both in one
/// pass where a term can: FusedEnergyGradient).

#include <algorithm>
#include <cmath>
#include <concepts>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "../../core/error.hpp"
#include "../../core/types.hpp"
#include "../dirichlet_boundary.hpp"

namespace simsr::physics::detail {

/// fixed[3v + c] = 1 for the boundary's vertices over n vertices (0 elsewhere). MeshError for a
/// vertex out of range.
template <class S>
void dirichlet_mask(Index n, const DirichletBoundary<S>& b, std::vector<char>& fixed) {
  fixed.assign(std::size_t(3 * n), 0);
  for (Index k = 0; k < b.vertices.size(); ++k) {
    const VIndex v = b.vertices[k];
    if (v < 0 || v >= n) throw MeshError("vertex", v, "Dirichlet vertex out of range [0, " + std::to_string(n) + ")");
    for (int c = 0; c < 3; ++c) fixed[std::size_t(3 * v + c)] = 1;
  }
}

/// Sets x's boundary vertices to their targets and their DOFs in `fixed` (dirichlet_mask).
/// ShapeError for a target array of the wrong shape, MeshError for a vertex out of range or a
/// non-finite target, ShapeError when x has a non-finite entry afterwards.
template <class S>
void apply_dirichlet(const char* solver, Points<S>& x, const DirichletBoundary<S>& b, std::vector<char>& fixed) {
  const Index n = x.rows();
  if (b.targets.rows() != b.vertices.size() || b.targets.cols() != 3)
    throw ShapeError(std::string(solver) + ": Dirichlet targets", {b.vertices.size(), 3}, {b.targets.rows(), b.targets.cols()});
  dirichlet_mask(n, b, fixed);
  for (Index k = 0; k < b.vertices.size(); ++k) {
    if (!b.targets.row(k).allFinite()) throw MeshError("vertex", b.vertices[k], "Dirichlet target is not finite");
    x.row(b.vertices[k]) = b.targets.row(k);
  }
  if (!x.allFinite()) throw ShapeError(std::string(solver) + ": x has non-finite entries", {n, 3}, {x.rows(), x.cols()});
}

/// The solvers' one stopping rule (NewtonOptions says it): ‖g‖ ≤ max(absolute, relative ·
/// reference), the reference the largest of reference_force, ‖g‖ at the first iterate and every
/// iterate's Σ_k ‖g_k‖ (the forces in balance).
class GradientTest {
 public:
  GradientTest(double relative, double absolute, double reference_force)
      : relative_(relative), absolute_(absolute), reference_(reference_force) {}
  /// The gradient norm below which the last iterate passed to converged() counts as converged.
  double threshold() const { return std::max(absolute_, relative_ * reference_); }
  /// Whether iterate `it` (gradient norm, forces' scale) has converged; call once per iterate.
  bool converged(Index it, double gradient_norm, double balance) {
    if (it == 0) reference_ = std::max(reference_, gradient_norm);
    reference_ = std::max(reference_, balance);
    return gradient_norm <= threshold();
  }

 private:
  double relative_, absolute_, reference_;
};

/// Σ terms' energies at x; `magnitude` gets Σ |E_k| (the scale of round-off in the sum).
template <class S, class P, class... Terms>
double total_energy(P policy, const Points<S>& x, double& magnitude, const Terms&... terms) {
  double sum = 0, mag = 0;
  const auto one = [&](const auto& t) {
    const double e = double(t.energy(policy, x));
    sum += e;
    mag += std::abs(e);
  };
  (one(terms), ...);
  magnitude = mag;
  return sum;
}

/// A term that computes its energy and adds its gradient in one pass (sharing the per-element
/// work, e.g. one SVD per tet instead of two): `E = term.add_energy_gradient(policy, x, g)`.
/// Optional: the sums below fall back to energy() and add_gradient().
template <class T, class S, class P>
concept FusedEnergyGradient = requires(const T& t, P p, const Points<S>& x, Points<S>& g) {
  { t.add_energy_gradient(p, x, g) } -> std::convertible_to<S>;
};

/// One term's energy at x, its gradient added to g, in one pass where the term offers it
/// (FusedEnergyGradient), else by energy() and add_gradient().
template <class S, class P, class T>
double add_energy_gradient(P policy, const T& term, const Points<S>& x, Points<S>& g) {
  if constexpr (FusedEnergyGradient<T, S, P>) {
    return double(term.add_energy_gradient(policy, x, g));
  } else {
    term.add_gradient(policy, x, g);
    return double(term.energy(policy, x));
  }
}

/// g += scratch over the free DOFs; returns ‖scratch‖ over them.
template <class S>
double add_free(const Points<S>& scratch, const std::vector<char>& fixed, VecX<S>& g) {
  const Eigen::Map<const VecX<S>> tg(scratch.data(), g.size());
  double sq = 0;
  for (Index k = 0; k < g.size(); ++k)
    if (!fixed[std::size_t(k)]) {
      g[k] += tg[k];
      sq += double(tg[k]) * double(tg[k]);
    }
  return std::sqrt(sq);
}

/// g = ∂E/∂x over the free DOFs (fixed ones 0), a 3V vector, vertex-major; returns Σ_k ‖∂E_k/∂x‖
/// over the free DOFs, the scale of the forces in balance. `scratch` is a #V×3 buffer.
template <class S, class P, class... Terms>
double free_gradient(P policy, const Points<S>& x, const std::vector<char>& fixed, Points<S>& scratch, VecX<S>& g,
                     const Terms&... terms) {
  const Index n = x.rows();
  g.setZero(3 * n);
  double balance = 0;
  const auto one = [&](const auto& term) {
    scratch.setZero(n, 3);
    term.add_gradient(policy, x, scratch);
    balance += add_free(scratch, fixed, g);
  };
  (one(terms), ...);
  return balance;
}

/// total_energy and free_gradient at one x in one pass over each term that offers
/// FusedEnergyGradient: returns Σ E_k; `magnitude` and `balance` as there.
template <class S, class P, class... Terms>
double energy_and_free_gradient(P policy, const Points<S>& x, const std::vector<char>& fixed, Points<S>& scratch, VecX<S>& g,
                                double& magnitude, double& balance, const Terms&... terms) {
  const Index n = x.rows();
  g.setZero(3 * n);
  double sum = 0, mag = 0, bal = 0;
  const auto one = [&](const auto& term) {
    scratch.setZero(n, 3);
    const double e = add_energy_gradient(policy, term, x, scratch);
    sum += e;
    mag += std::abs(e);
    bal += add_free(scratch, fixed, g);
  };
  (one(terms), ...);
  magnitude = mag;
  balance = bal;
  return sum;
}

}  // namespace simsr::physics::detail
