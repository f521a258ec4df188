#pragma once
/// \file
/// The local–global solver of projective dynamics (Bouaziz et al. 2014), over the same terms as
/// the Newton solver (quasistatic.hpp), in the quasi-Newton form of Liu, Bouaziz & Kavan 2017:
///
///   global matrix  L = Σ_k L_k, each term's constant matrix (add_global_matrix: w AᵀA of a
///                  projective term, a stated stand-in for the others), Dirichlet DOFs eliminated,
///                  factored once per weight set (and per boundary vertex set); where every
///                  block is c·I (SoftDECA's terms) it is A ⊗ I₃ and only the #V×#V A is
///                  factored, the coordinates solved one by one;
///   local step     every term's gradient at x, which for a projective term is L_k x − w Aᵀp
///                  with p the projections (strain band, sphere, curvature magnitude), computed per
///                  element in parallel under the policy;
///   global step    d = −L⁻¹ g, refined by L-BFGS over the last `history` steps (0: none);
///   line search    backtracking on the total energy from the unit step (the unit step's
///                  energy and gradient in one pass: FusedEnergyGradient).
///
/// With history 0 and only projective terms this is Bouaziz et al.'s iteration x ← L⁻¹(Σ w Aᵀp)
/// exactly: the unit step minimizes the quadratic that majorizes E at x, so it is always accepted.
/// Non-projective terms (VolumeTarget's (det F − v)²) enter through their exact gradient, so the
/// fixed point is the minimum of the very energy Newton minimizes; L only has to be a good
/// preconditioner, never exact, which is also why a weight changed without refactoring still
/// converges to the right answer (slower): call invalidate() after changing weights.
///
///     physics::LocalGlobalSolver<> pd(mesh.num_vertices(), mesh.T);
///     auto report = pd.solve(exec::omp, x, bc, strain, volume, bending, targets, gravity, dynamics);
///
/// Every term must be a ProjectiveTerm: an EnergyTerm with add_global_matrix(policy, BlockHessian&).

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "detail/term_sums.hpp"
#include "dirichlet_boundary.hpp"
#include "energy_term.hpp"
#include "hessian.hpp"
#include "linear_solvers/linear_solvers.hpp"

namespace simsr::physics {

namespace detail {
template <class T, class S>
concept HasGlobalMatrix = requires(const T& t, BlockHessian<S>& L) {
  t.add_global_matrix(exec::seq, L);
  t.add_global_matrix(exec::omp, L);
};
}  // namespace detail

/// An EnergyTerm the local–global solver can use: it also adds its constant matrix.
template <class T, class S = Scalar>
concept ProjectiveTerm = EnergyTerm<T, S> && detail::HasGlobalMatrix<T, S>;

/// `static_assert(assert_projective_term<T, S>())`: one sentence when T is not a ProjectiveTerm.
template <class T, class S = Scalar>
constexpr bool assert_projective_term() {
  static_assert(EnergyTerm<T, S>, "this type is not a physics::ProjectiveTerm: it is not a physics::EnergyTerm (energy, add_gradient, add_hessian)");
  static_assert(!EnergyTerm<T, S> || detail::HasGlobalMatrix<T, S>,
                "this type is not a physics::ProjectiveTerm: it lacks add_global_matrix(policy, BlockHessian& L) const for exec::seq and "
                "exec::omp, its constant matrix in the local-global solver (ElasticEnergy has it for materials with projective_stiffness())");
  return true;
}

/// One iteration, as reported to the progress callback and kept in the report's history.
struct LocalGlobalIteration {
  Index iteration = 0;
  double energy = 0;         ///< total energy before the step (J)
  double gradient_norm = 0;  ///< ‖∂E/∂x‖ over free DOFs before the step (N)
  double step_length = 0;    ///< accepted line-search factor
  Index backtracks = 0;
};

/// Options of LocalGlobalSolver. The convergence test is the Newton solver's (NewtonOptions), so
/// both stop at the same gradient norm on the same problem.
struct LocalGlobalOptions {
  double relative_tolerance = 1e-6;
  double absolute_tolerance = 0;  ///< N
  double reference_force = 0;     ///< N
  Index max_iterations = 2000;
  /// L-BFGS memory (step pairs). 0 is plain projective dynamics (with the line search);
  /// Liu et al. 2017 use 5.
  Index history = 5;
  double armijo = 1e-4;
  Index max_backtracks = 40;
  /// When every block of the global matrix is c·I (all of SoftDECA's terms: tets, targets,
  /// bending, inertia), factor the #V×#V matrix of the c's and solve x, y and z one after the
  /// other: a third of the unknowns and a ninth of the nonzeros of the 3V×3V matrix, whose
  /// ordering cannot see that the coordinates decouple. false: always the 3V×3V matrix.
  bool isotropic_reduction = true;
  std::function<void(const LocalGlobalIteration&)> progress = {};
};

/// What a solve did.
struct LocalGlobalReport {
  bool converged = false;
  Index iterations = 0;
  double energy = 0;
  double initial_gradient_norm = 0;
  double gradient_norm = 0;
  bool factored = false;  ///< this solve factored the global matrix (the first with its weights)
  std::vector<LocalGlobalIteration> history;
};

/// Projective dynamics' local–global iteration, quasi-Newton form (see the file comment).
template <class Linear = SparseCholesky<Scalar>>
class LocalGlobalSolver {
  static_assert(assert_linear_solver<Linear>());

 public:
  using S = typename detail::linear_scalar<Linear>::type;

  /// The matrix's pattern starts from the tets (the elastic terms' blocks) and grows to what the
  /// other terms add.
  LocalGlobalSolver(Index num_vertices, const Tets& T, LocalGlobalOptions options = {}, Linear linear = {})
      : n_(num_vertices), options_(std::move(options)), linear_(std::move(linear)), L_(num_vertices, T) {}

  LocalGlobalOptions& options() { return options_; }
  /// The weights changed: the next solve factors the global matrix again.
  void invalidate() { factored_ = false; }
  bool factored() const { return factored_; }
  /// Whether the last factorization was of the #V×#V matrix (LocalGlobalOptions::isotropic_reduction).
  bool reduced() const { return reduced_; }
  Index factorizations() const { return factorizations_; }

  /// Builds and factors L from the terms (Dirichlet DOFs of `boundary` eliminated). solve() calls
  /// it when needed; call it directly to time or reuse the factorization.
  template <exec::HostPolicy P, class... Terms>
  void factor(P policy, const DirichletBoundary<S>& boundary, const Terms&... terms) {
    static_assert((assert_projective_term<Terms, S>() && ...));
    if constexpr ((ProjectiveTerm<Terms, S> && ...)) {
      detail::dirichlet_mask(n_, boundary, factor_fixed_);
      L_.set_zero();
      (terms.add_global_matrix(policy, L_), ...);
      reduced_ = options_.isotropic_reduction && L_.isotropic();
      if (reduced_) {
        fixed_vertices_.resize(std::size_t(n_));
        for (Index v = 0; v < n_; ++v) fixed_vertices_[std::size_t(v)] = factor_fixed_[std::size_t(3 * v)];
        linear_.compute(policy, L_.assemble_isotropic(policy, fixed_vertices_), L_.isotropic_pattern_version());
      } else {
        linear_.compute(policy, L_.assemble(policy, factor_fixed_), L_.pattern_version());
      }
      factored_ = true;
      ++factorizations_;
    }
  }

  /// d = L⁻¹ q with the factored matrix (one global step without L-BFGS; q and d 3V, vertex-major,
  /// zero on Dirichlet DOFs). Error before the first factorization.
  template <exec::HostPolicy P>
  void apply_inverse(P policy, const VecX<S>& q, VecX<S>& d) {
    if (!factored_) throw Error("LocalGlobalSolver::apply_inverse before the matrix was factored (factor() or solve())");
    if (q.size() != 3 * n_) throw ShapeError("LocalGlobalSolver::apply_inverse: q", {3 * n_}, {q.size()});
    global_solve(policy, q, d);
  }

  /// Minimizes Σ terms over x (#V×3, in/out: the warm start), boundary vertices set first.
  /// Throws ConvergenceError when the tolerance is not met within max_iterations or the line
  /// search finds no decrease; ConvergenceError from the linear solver when L is singular (a
  /// body with neither Dirichlet vertices nor a term that holds it: rigid motions are free).
  template <exec::HostPolicy P, class... Terms>
  LocalGlobalReport solve(P policy, Points<S>& x, const DirichletBoundary<S>& boundary, const Terms&... terms) {
    static_assert(sizeof...(Terms) > 0, "LocalGlobalSolver::solve needs at least one energy term");
    static_assert((assert_projective_term<Terms, S>() && ...));
    if constexpr ((ProjectiveTerm<Terms, S> && ...))
      return iterate(policy, x, boundary, terms...);
    else
      return {};
  }

 private:
  template <class P, class... Terms>
  LocalGlobalReport iterate(P policy, Points<S>& x, const DirichletBoundary<S>& boundary, const Terms&... terms) {
    detail::require_positions("LocalGlobalSolver::solve: x", x, n_);
    detail::apply_dirichlet("LocalGlobalSolver", x, boundary, fixed_);
    LocalGlobalReport report;
    if (!factored_ || fixed_ != factor_fixed_) {
      factor(policy, boundary, terms...);
      report.factored = true;
    }
    forget();
    detail::GradientTest test(options_.relative_tolerance, options_.absolute_tolerance, options_.reference_force);
    double magnitude = 0, balance = 0;
    double E = detail::energy_and_free_gradient(policy, x, fixed_, scratch_, g_, magnitude, balance, terms...);
    for (Index it = 0;; ++it) {
      if (!std::isfinite(E)) throw ConvergenceError("local-global solver (energy is not finite at iteration " + std::to_string(it) + ")", it, E);
      const double gnorm = double(g_.norm());
      if (it == 0) report.initial_gradient_norm = gnorm;
      report.iterations = it;
      report.energy = E;
      report.gradient_norm = gnorm;
      if (test.converged(it, gnorm, balance)) {
        report.converged = true;
        return report;
      }
      if (it >= options_.max_iterations) throw ConvergenceError("local-global solver", it, gnorm);

      direction(policy);
      double slope = double(g_.dot(d_));
      if (!(slope < 0) || !d_.allFinite()) {  // the L-BFGS update lost descent: the plain global step
        forget();
        direction(policy);
        slope = double(g_.dot(d_));
      }
      if (!(slope < 0)) throw ConvergenceError("local-global solver (the global step is no descent direction: L is not positive definite)", it, gnorm);

      const double noise = 64 * std::numeric_limits<double>::epsilon() * magnitude;
      // The unit step, usually accepted, is evaluated with its gradient in one pass (one SVD
      // per tet for the strain term, not one for the energy and another for the gradient);
      // backtracking steps with the energy alone.
      double alpha = 1, Et = 0, trial_balance = 0;
      Index backtracks = 0;
      for (;; ++backtracks) {
        trial_ = x;
        Eigen::Map<VecX<S>>(trial_.data(), 3 * n_) += S(alpha) * d_;
        double mag = 0;
        if (backtracks == 0)
          Et = detail::energy_and_free_gradient(policy, trial_, fixed_, scratch_, g_trial_, mag, trial_balance, terms...);
        else
          Et = detail::total_energy(policy, trial_, mag, terms...);
        if (std::isfinite(Et) && Et <= E + options_.armijo * alpha * slope + noise) {
          magnitude = mag;
          break;
        }
        if (backtracks >= options_.max_backtracks)
          throw ConvergenceError("local-global solver (line search: no decrease at iteration " + std::to_string(it) + ")", it, gnorm);
        alpha *= 0.5;
      }
      x.swap(trial_);
      g_old_.swap(g_);
      if (backtracks == 0) {
        g_.swap(g_trial_);
        balance = trial_balance;
      } else {
        balance = detail::free_gradient(policy, x, fixed_, scratch_, g_, terms...);
      }
      remember(alpha);
      LocalGlobalIteration record{it, E, gnorm, alpha, backtracks};
      report.history.push_back(record);
      if (options_.progress) options_.progress(record);
      E = Et;
    }
  }

  /// d_ = −H̃⁻¹ g_ by L-BFGS's two loops with L⁻¹ as the initial inverse Hessian. The pairs live
  /// in a ring of `history` slots allocated once per solve size: an iteration allocates nothing.
  template <class P>
  void direction(P policy) {
    q_ = g_;
    alphas_.resize(std::size_t(stored_));
    for (Index k = stored_; k-- > 0;) {  // newest first
      const std::size_t i = slot(k);
      alphas_[std::size_t(k)] = rho_[i] * s_[i].dot(q_);
      q_ -= alphas_[std::size_t(k)] * y_[i];
    }
    global_solve(policy, q_, d_);
    for (Index k = 0; k < stored_; ++k) {  // oldest first
      const std::size_t i = slot(k);
      d_ += (alphas_[std::size_t(k)] - rho_[i] * y_[i].dot(d_)) * s_[i];
    }
    d_ = -d_;
  }

  /// d = L⁻¹ q: one 3V solve, or three #V solves with the reduced matrix (one per coordinate).
  template <class P>
  void global_solve(P policy, const VecX<S>& q, VecX<S>& d) {
    const auto check = [](const LinearSolveInfo& info) {
      if (!info.converged)
        throw ConvergenceError("local-global solver (global step: the linear solve did not converge)", info.iterations, info.relative_residual);
    };
    if (!reduced_) {
      check(linear_.solve(policy, q, d));
      return;
    }
    d.resize(3 * n_);
    qc_.resize(n_);
    for (int c = 0; c < 3; ++c) {
      qc_ = Eigen::Map<const VecX<S>, 0, Eigen::InnerStride<3>>(q.data() + c, n_);
      check(linear_.solve(policy, qc_, dc_));
      Eigen::Map<VecX<S>, 0, Eigen::InnerStride<3>>(d.data() + c, n_) = dc_;
    }
  }

  /// The k-th stored pair, oldest first.
  std::size_t slot(Index k) const { return std::size_t((first_ + k) % Index(s_.size())); }

  void forget() {
    stored_ = 0;
    first_ = 0;
    const std::size_t m = std::size_t(std::max<Index>(options_.history, 0));
    if (s_.size() != m || (m > 0 && s_[0].size() != 3 * n_)) {
      s_.assign(m, VecX<S>::Zero(3 * n_));
      y_.assign(m, VecX<S>::Zero(3 * n_));
      rho_.assign(m, S(0));
    }
  }

  /// Keeps the step s_k = x_{k+1} − x_k (alpha · d_) and y_k = g_{k+1} − g_k (g_ − g_old_) when
  /// yᵀs > 0 (the update stays positive definite), the oldest pair giving way.
  void remember(double alpha) {
    if (s_.empty()) return;
    const S ys = S(alpha) * (g_ - g_old_).dot(d_);  // Eigen evaluates these expressions without temporaries
    const double yy = double((g_ - g_old_).squaredNorm()), ss = alpha * alpha * double(d_.squaredNorm());
    if (!(ys > S(1e-12) * std::sqrt(yy * ss))) return;
    const std::size_t i = stored_ < Index(s_.size()) ? slot(stored_) : slot(0);
    s_[i] = S(alpha) * d_;
    y_[i] = g_ - g_old_;
    rho_[i] = S(1) / ys;
    if (stored_ < Index(s_.size()))
      ++stored_;
    else
      first_ = (first_ + 1) % Index(s_.size());
  }

  Index n_;
  LocalGlobalOptions options_;
  Linear linear_;
  BlockHessian<S> L_;
  bool factored_ = false, reduced_ = false;
  Index factorizations_ = 0;
  std::vector<char> fixed_, factor_fixed_, fixed_vertices_;
  VecX<S> qc_, dc_;  // one coordinate of the reduced solve
  Points<S> scratch_, trial_;
  VecX<S> g_, g_old_, g_trial_, d_, q_;
  std::vector<VecX<S>> s_, y_;  // the L-BFGS ring (forget, remember)
  std::vector<S> rho_, alphas_;
  Index stored_ = 0, first_ = 0;
};

}  // namespace simsr::physics
