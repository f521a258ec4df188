#pragma once
/// \file
/// The second-order effects of SoftDECA's simulation (softdeca supplement §1 "Dynamics": α, β,
/// γ ∈ [0, 2]) as one EnergyTerm, the incremental potential of an implicit (backward Euler) step
/// of length h (Martin et al. 2011; Bouaziz et al. 2014 eq. 4):
///
///     E(x) = α/(2h²) ‖x − x̂‖²_M + β/(2h²) ‖x − x_n‖²_M,   x̂ = x_n + γ (x_n − x_{n−1})
///
///   α  inertia: 1 is backward Euler's ‖x − x̂‖²_M/(2h²), 0 removes inertia;
///   β  damping: a drag on the step's velocity (x − x_n)/h, force −β M (x − x_n)/h²; it slows the
///      body toward x_n without a preferred direction (β = 1 weighs like α = 1 with no momentum);
///   γ  momentum: the share of the last step's velocity carried into the prediction x̂
///      (1: Newton's first law, 0: every step starts from rest; only matters when α > 0).
/// α = β = 0 is the quasistatic problem whatever γ. M is the lumped mass (the Gravity term's
/// masses). Its Hessian (α + β) M/h² is constant: it enters the local–global solver's matrix as it
/// is, and the matrix changes with α, β, h (refactor when they do).
///
///     physics::ImplicitInertia<> dyn(gravity.masses(), rest_positions, {.h = 1.0 / 30, .alpha = 1, .beta = 0.1, .gamma = 1});
///     solver.solve(exec::omp, x, bc, strain, volume, gravity, dyn);   // then:
///     dyn.advance(x);                                                // x becomes x_n

#include <string>
#include <utility>

#include <Eigen/Core>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../energy_term.hpp"
#include "detail/checks.hpp"

namespace simsr::physics {

/// α, β, γ and the step h of ImplicitInertia.
struct DynamicsParameters {
  double h = 1.0 / 30;  ///< s, > 0
  double alpha = 0;     ///< inertia weight, ≥ 0
  double beta = 0;      ///< damping weight, ≥ 0
  double gamma = 0;     ///< momentum share, ≥ 0
  bool quasistatic() const { return alpha == 0 && beta == 0; }
};

/// The implicit step's inertia and damping potential (see the file comment).
template <class S = Scalar>
class ImplicitInertia {
 public:
  using scalar_type = S;

  /// `masses` #V (kg, ≥ 0), `rest` #V×3: x_{n−1} = x_n = rest (the body starts at rest).
  ImplicitInertia(VecX<S> masses, const Points<S>& rest, DynamicsParameters parameters) : m_(std::move(masses)) {
    detail::require_nonnegative_each("ImplicitInertia: masses", m_, m_.size());
    set_parameters(parameters);
    reset(rest);
  }

  Index num_vertices() const { return m_.size(); }
  const DynamicsParameters& parameters() const { return p_; }
  /// Changes the local–global solver's matrix when α, β or h change.
  void set_parameters(DynamicsParameters p) {
    detail::require_positive("ImplicitInertia: time step h", p.h);
    detail::require_nonnegative("ImplicitInertia: alpha", p.alpha);
    detail::require_nonnegative("ImplicitInertia: beta", p.beta);
    detail::require_nonnegative("ImplicitInertia: gamma", p.gamma);
    p_ = p;
  }
  /// x_{n−1} = x_n = x (at rest at x).
  void reset(const Points<S>& x) {
    detail::require_finite_matrix("ImplicitInertia: positions", x, num_vertices(), 3);
    previous_ = x;
    current_ = x;
  }
  /// The step is taken: x_{n−1} ← x_n, x_n ← x.
  void advance(const Points<S>& x) {
    detail::require_finite_matrix("ImplicitInertia: new positions", x, num_vertices(), 3);
    previous_.swap(current_);
    current_ = x;
  }
  const Points<S>& current() const { return current_; }
  const Points<S>& previous() const { return previous_; }
  /// x̂ = x_n + γ (x_n − x_{n−1}).
  Vec3<S> prediction(Index v) const { return (current_.row(v) + S(p_.gamma) * (current_.row(v) - previous_.row(v))).transpose(); }

  template <exec::HostPolicy P>
  S energy(P policy, const Points<S>& x) const {
    physics::detail::require_positions("ImplicitInertia::energy: x", x, num_vertices());
    if (p_.quasistatic()) return S(0);
    const S ih2 = S(0.5) / S(p_.h * p_.h);
    return exec::parallel_reduce(
        policy, num_vertices(), S(0),
        [&](Index v) {
          const Vec3<S> xv = x.row(v).transpose();
          return m_[v] * ih2 * (S(p_.alpha) * (xv - prediction(v)).squaredNorm() + S(p_.beta) * (xv - current_.row(v).transpose()).squaredNorm());
        },
        [](S a, S b) { return a + b; });
  }

  template <exec::HostPolicy P>
  void add_gradient(P policy, const Points<S>& x, Points<S>& g) const {
    physics::detail::require_positions("ImplicitInertia::add_gradient: x", x, num_vertices());
    physics::detail::require_positions("ImplicitInertia::add_gradient: g", g, num_vertices());
    if (p_.quasistatic()) return;
    const S ih2 = S(1) / S(p_.h * p_.h);
    exec::parallel_for(policy, num_vertices(), [&](Index v) {
      const Vec3<S> xv = x.row(v).transpose();
      g.row(v) += (m_[v] * ih2 * (S(p_.alpha) * (xv - prediction(v)) + S(p_.beta) * (xv - current_.row(v).transpose()))).transpose();
    });
  }

  template <exec::HostPolicy P>
  void add_hessian(P policy, const Points<S>& x, BlockHessian<S>& H, Definiteness) const {
    physics::detail::require_positions("ImplicitInertia::add_hessian: x", x, num_vertices());
    add_global_matrix(policy, H);
  }

  /// (α + β) M/h², the same as the Hessian (constant).
  template <exec::HostPolicy P>
  void add_global_matrix(P, BlockHessian<S>& L) const {
    if (p_.quasistatic()) return;
    const S c = S((p_.alpha + p_.beta) / (p_.h * p_.h));
    for (Index v = 0; v < num_vertices(); ++v) L.add(VIndex(v), VIndex(v), c * m_[v] * Mat3<S>::Identity());
  }

 private:
  VecX<S> m_;
  DynamicsParameters p_;
  Points<S> previous_, current_;
};

static_assert(assert_energy_term<ImplicitInertia<double>, double>());

}  // namespace simsr::physics
