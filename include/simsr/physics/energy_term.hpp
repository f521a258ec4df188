#pragma once
/// \file
/// The EnergyTerm concept: one potential of a quasistatic problem (elasticity, springs, gravity,
/// contact). The solver minimizes the sum of the terms it is given, over the positions x (#V×3).
/// Every term implements the same three calls, the execution policy first:
///
///     double e = term.energy(policy, x);
///     term.add_gradient(policy, x, g);        // g += ∂E/∂x, #V×3
///     term.add_hessian(policy, x, H, d);      // H += ∂²E/∂x² (BlockHessian, hessian.hpp)
///
/// `d` is always passed: Definiteness::exact asks for the true Hessian where the term has one
/// (the elastic energy), Definiteness::project for a positive semi-definite one (Newton's fallback);
/// terms whose Hessian is PSD anyway (springs, contact, gravity) give the same blocks for both.
/// H is the one Hessian sink: scattered blocks go through `H.add(i, j, block)` (any vertex pair;
/// pairs outside the pattern grow it), a term that fills the tets' pattern writes
/// `H.block(H.slot(i, j))` directly (the elastic energy's allocation-free parallel gather).
///
/// Terms are stateless between calls (they may own scratch buffers) and never throw on a
/// configuration the solver can reach (inverted elements included). A term may ignore the policy
/// (sequential springs); it still takes it, so one call shape serves every term.

#include <concepts>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/exec/policy.hpp"
#include "../core/types.hpp"
#include "hessian.hpp"
#include "materials/material.hpp"

namespace simsr::physics {

namespace detail {
template <class T, class S>
concept HasTermEnergy = requires(const T& t, const Points<S>& x) {
  { t.energy(exec::seq, x) } -> std::convertible_to<S>;
  { t.energy(exec::omp, x) } -> std::convertible_to<S>;
};
template <class T, class S>
concept HasTermGradient = requires(const T& t, const Points<S>& x, Points<S>& g) {
  t.add_gradient(exec::seq, x, g);
  t.add_gradient(exec::omp, x, g);
};
template <class T, class S>
concept HasTermHessian = requires(const T& t, const Points<S>& x, BlockHessian<S>& H, Definiteness d) {
  t.add_hessian(exec::seq, x, H, d);
  t.add_hessian(exec::omp, x, H, d);
};
}  // namespace detail

/// A potential the quasistatic solver can minimize (see the file comment).
template <class T, class S = Scalar>
concept EnergyTerm = detail::HasTermEnergy<T, S> && detail::HasTermGradient<T, S> && detail::HasTermHessian<T, S>;

/// `static_assert(assert_energy_term<T, S>())`: a type that is not an EnergyTerm stops the build
/// with one sentence naming the first call it lacks (and nothing else: the function returns true
/// once its own assertion has spoken).
template <class T, class S = Scalar>
constexpr bool assert_energy_term() {
  using namespace detail;
  constexpr int lacks = !HasTermEnergy<T, S> ? 0 : !HasTermGradient<T, S> ? 1 : !HasTermHessian<T, S> ? 2 : -1;
  static_assert(lacks != 0, "this type is not a physics::EnergyTerm: it lacks energy(policy, const Points& x) const -> scalar for exec::seq "
                            "and exec::omp");
  static_assert(lacks != 1, "this type is not a physics::EnergyTerm: it lacks add_gradient(policy, const Points& x, Points& g) const for "
                            "exec::seq and exec::omp");
  static_assert(lacks != 2, "this type is not a physics::EnergyTerm: it lacks add_hessian(policy, const Points& x, BlockHessian& H, "
                            "Definiteness d) const for exec::seq and exec::omp, the one Hessian form every term implements");
  return true;
}

namespace detail {
/// Throws ShapeError unless x is #V×3 with the expected vertex count.
template <class D>
void require_positions(const char* what, const Eigen::MatrixBase<D>& x, Index num_vertices) {
  if (x.rows() != num_vertices || x.cols() != 3) throw ShapeError(what, {num_vertices, 3}, {x.rows(), x.cols()});
}
}  // namespace detail

}  // namespace simsr::physics
