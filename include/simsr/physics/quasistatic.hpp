#pragma once
/// \file
/// Quasistatic solver (SPEC §3, Park et al. 2023 §4: both simulators are quasistatic): minimize
/// the total potential Σ E_k(x) over the free vertices, bones held by Dirichlet conditions, by
/// Newton's method with a backtracking (Armijo) line search on the total energy. The Hessian is
/// the terms' exact one where it is positive definite and their definiteness-fixed one otherwise,
/// so every Newton direction descends. Warm start: x comes in as the previous frame's solution and
/// leaves as this frame's.
///
///     physics::QuasistaticSolver<physics::SparseCholesky<>> newton(mesh.num_vertices(), mesh.T);
///     auto report = newton.solve(exec::omp, x, bones.boundary(), elastic, gravity, tracks);   // throws ConvergenceError
///
/// The linear solver is a type (LinearSolver concept): SparseCholesky, or ConjugateGradient with
/// Jacobi / BlockJacobi / IncompleteCholesky / Multigrid preconditioning. The execution policy is
/// the first argument of solve() and reaches everything the solve runs: every term's energy,
/// gradient and Hessian, the assembly, and the linear solver's compute and solve.

#include <algorithm>
#include <chrono>
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

/// One Newton iteration, as reported to a progress callback and kept in NewtonReport::history.
struct NewtonIteration {
  Index iteration = 0;
  double energy = 0;              ///< total energy before the step (J)
  double gradient_norm = 0;       ///< ‖∂E/∂x‖ over free DOFs before the step (N)
  double step_length = 0;         ///< accepted line-search factor α
  Index backtracks = 0;
  Index linear_iterations = 0;
  double linear_residual = 0;
  double linear_tolerance = 0;    ///< the relative tolerance the linear solve was given (iterative solvers; 0: none)
  double tolerance = 0;           ///< the gradient norm that counts as converged at this iteration (N)
  bool projected = false;         ///< the definiteness-fixed Hessian was used
  double shift = 0;               ///< Hessian::regularized: the τ of H + τ·mean|diag H|·I used (0: H itself)
  bool chord = false;             ///< NewtonOptions::chord_below: solved with the previous iteration's Hessian
};

/// Options of QuasistaticSolver.
struct NewtonOptions {
  /// Converged when ‖g‖ ≤ max(absolute_tolerance, relative_tolerance · reference): reference is
  /// the largest of reference_force, ‖g‖ at the start of this solve, and Σ_k ‖g_k‖ over the terms
  /// at the current iterate (the forces in balance: a warm start that is already the solution of
  /// a loaded body converges at once instead of chasing round-off).
  double relative_tolerance = 1e-6;
  double absolute_tolerance = 0;  ///< N
  double reference_force = 0;     ///< N
  /// Also converged when a Newton step (from a converged linear solve) moves no vertex by more
  /// than step_tolerance × the bounding-box diagonal: the iterate is then the minimum to within
  /// round-off of the positions, even where no force scale exists (an unloaded body at rest).
  double step_tolerance = 1e-13;
  Index max_iterations = 100;
  /// After max_iterations, return the iterate (report.converged false) instead of throwing
  /// ConvergenceError: an inexact Newton with a fixed budget. max_iterations = 1 is one Newton
  /// step with line search per solve; for a backward-Euler step that is the linearized implicit
  /// Euler of Baraff & Witkin 1998 (what ARCSim, the thin-shell paper's cloth simulator, takes),
  /// one factorization per step. A line search that finds no decrease still throws.
  bool accept_at_max_iterations = false;
  double armijo = 1e-4;           ///< sufficient decrease: E(x+αd) ≤ E(x) + armijo·α·gᵀd
  Index max_backtracks = 40;      ///< each halves α
  /// Which Hessian the Newton systems use. `adaptive` tries the exact Hessian first and falls back
  /// to the projected one (Teran 2005's definiteness fix) in an iteration where it is not positive
  /// definite (a Cholesky pivot ≤ 0, negative curvature met by CG, or no descent). Always
  /// projecting is robust but slow near the solution: under bending, the compressed side's
  /// geometric stiffness is negative and clamping it stalls Newton at linear convergence
  /// (measured on the cantilever: ‖g‖ 3.9e-5 → 3.6e-5 per iteration).
  ///
  /// `regularized` tries the exact Hessian first too, and where it is not positive definite
  /// shifts it, H + τ·m·I on the free DOFs (m the mean |diagonal|; τ = 10⁻³, 10⁻², … up to 10²,
  /// Levenberg–Marquardt's damping), before falling back to the projected one. After an
  /// iteration that needed τ > 10⁻³ the next one starts at τ/10 and does not try H itself (it
  /// stays indefinite from one iteration to the next; each failed try is a factorization). The shift keeps
  /// the negative curvature of compression as a smaller step instead of dropping it: on the DISK
  /// tablecloth (7,057 vertices, hanging in folds in wind), where the projected fallback stalled
  /// and halved steps, Newton took 253 iterations over 10 frames instead of 468, none halved
  /// (README, "Thin shells"). Not better everywhere: a crumpled membrane solved back to rest from
  /// far away took 119 iterations against adaptive's 41 (bench_physics, BM_newton_crumpled_1089).
  enum class Hessian { projected, adaptive, regularized } hessian = Hessian::adaptive;
  /// The linear solves' relative tolerance, for iterative solvers (ConjugateGradient: its
  /// options().tolerance). `fixed`: the solver's own in every iteration. `adaptive`: an inexact
  /// Newton (Eisenstat & Walker 1996, choice 2): η_0 = forcing_max, then η_k = 0.9 (‖g_k‖ /
  /// ‖g_{k−1}‖)², kept at least 0.9 η_{k−1}² while that is above 0.1 (their safeguard), at most
  /// forcing_max and at least the solver's own tolerance. Far from the solution a loose solve
  /// gives nearly the same step for a fraction of the iterations; near it the ratio is small and
  /// the solves tighten to the solver's own tolerance, keeping Newton's fast local convergence.
  enum class Forcing { fixed, adaptive } forcing = Forcing::fixed;
  double forcing_max = 0.1;
  /// Forcing::adaptive also keeps η_k ≥ ½ τ / ‖g_k‖, τ the gradient norm that counts as converged
  /// (Kelley 1995, "Iterative Methods for Linear and Nonlinear Equations", §6.3.2, eq. 6.20): a
  /// linear solve need not make the next gradient much smaller than τ, so the last iterations stop
  /// oversolving. Where Newton's own contraction is limited (a material whose second derivative
  /// jumps, as the passive fibre curve's at λ = 1), the final solve then takes a few PCG
  /// iterations instead of a full solve to the solver's tolerance (bench_physics,
  /// BM_frame_73k/…_inexact…). false: Eisenstat–Walker's choice alone (the baseline).
  bool forcing_safeguard = true;
  /// Chord steps (Shamanskii's modified Newton; Kelley 1995 §5.4.3 / Kelley 2003 §2.3): an
  /// iteration whose gradient norm is at most chord_below × the previous iteration's solves with
  /// the previous iteration's Hessian and linear-solver setup (factorization, multigrid levels)
  /// instead of assembling and setting up anew. A gradient that fell that much says Newton is in
  /// its fast local phase, where the iterate moved little and the Hessian with it: the old one
  /// still gives a step that contracts by about ‖H_old⁻¹(H − H_old)‖, enough for a last step that
  /// only has to reach the tolerance, for the price of a solve. It is adaptive by construction:
  /// a chord step that contracts less than chord_below makes the next iteration a full Newton one,
  /// and the line search still guards every step. Only after a converged linear solve. 0: off
  /// (every iteration assembles its Hessian: the baseline).
  double chord_below = 0;
  /// A chord step across solves: the first iteration of a solve solves with the Hessian and
  /// linear-solver setup of the previous solve's last iteration, when that setup is still held
  /// (its linear solve converged, nothing threw since) and the Dirichlet DOFs are the same ones.
  /// In a sequence of quasistatic frames the previous solve is the previous frame, whose last
  /// Hessian was assembled near its solution: one frame step away from this frame's warm start,
  /// so the first step (solved loosely anyway under Forcing::adaptive) costs a solve instead of a
  /// Hessian and a multigrid setup. The same guards as chord_below: a solve that does not converge
  /// or does not descend makes it a full Newton iteration, and the line search guards the step.
  /// The caller vouches that the terms are the same kind of terms as in the previous solve (a
  /// changed material constant only makes the reused matrix a worse preconditioned model; the
  /// gradient, and so the equilibrium, is always this solve's). false: off (the baseline).
  bool chord_first = false;
  /// Called after every iteration (progress lines for long runs).
  std::function<void(const NewtonIteration&)> progress;
};

/// "projected", "adaptive" or "regularized" (reports and dataset summaries).
inline const char* hessian_name(NewtonOptions::Hessian h) {
  switch (h) {
    case NewtonOptions::Hessian::projected: return "projected";
    case NewtonOptions::Hessian::adaptive: return "adaptive";
    case NewtonOptions::Hessian::regularized: return "regularized";
  }
  return "unknown";
}

/// Where a solve's time went (wall-clock seconds, steady_clock): the terms' energies (the first
/// iterate's and every line-search trial's), their gradients, the Hessian assembly (every term's
/// blocks and BlockHessian::assemble), the linear solver's setup (a factorization, a
/// preconditioner's compute) and its solves. What is left of the solve's total is the
/// iteration's own vector work (the trial point, the step).
struct NewtonSeconds {
  double energy = 0, gradient = 0, hessian = 0, linear_setup = 0, linear_solve = 0;
  double total = 0;  ///< the whole solve
};

/// What a solve did.
struct NewtonReport {
  bool converged = false;
  Index iterations = 0;
  double energy = 0;
  double initial_gradient_norm = 0;
  double gradient_norm = 0;
  Index linear_iterations = 0;
  std::vector<NewtonIteration> history;
  NewtonSeconds seconds;  ///< where the time went
};

/// Newton with line search over a sum of EnergyTerms (see the file comment).
template <class Linear = SparseCholesky<Scalar>>
class QuasistaticSolver {
  static_assert(assert_linear_solver<Linear>());

 public:
  using S = typename detail::linear_scalar<Linear>::type;

  /// The Hessian pattern comes from the tets (every term coupling vertices within one tet fits it).
  QuasistaticSolver(Index num_vertices, const Tets& T, NewtonOptions options = {}, Linear linear = {})
      : n_(num_vertices), options_(std::move(options)), linear_(std::move(linear)), H_(num_vertices, T) {}

  NewtonOptions& options() { return options_; }
  Linear& linear_solver() { return linear_; }
  const BlockHessian<S>& hessian() const { return H_; }

  /// Minimizes Σ terms over x (#V×3, in/out: the warm start) under `policy`, with x of the
  /// boundary's vertices set to their targets first. Every term must be a physics::EnergyTerm.
  /// Throws ConvergenceError (iterations, gradient norm) when the tolerance is not met within
  /// max_iterations or the line search cannot decrease the energy. seq and omp give bitwise
  /// identical iterates.
  template <exec::HostPolicy P, class... Terms>
  NewtonReport solve(P policy, Points<S>& x, const DirichletBoundary<S>& boundary, const Terms&... terms) {
    static_assert(sizeof...(Terms) > 0, "QuasistaticSolver::solve needs at least one energy term");
    static_assert((assert_energy_term<Terms, S>() && ...));
    if constexpr ((EnergyTerm<Terms, S> && ...))
      return newton(policy, x, boundary, terms...);
    else
      return {};
  }

  /// ∂E/∂x at the last iterate of the last solve (free DOFs; fixed ones 0), 3V, vertex-major.
  const VecX<S>& gradient() const { return g_; }

 private:
  /// The Newton loop of solve(), once every term is known to be an EnergyTerm.
  template <class P, class... Terms>
  NewtonReport newton(P policy, Points<S>& x, const DirichletBoundary<S>& boundary, const Terms&... terms) {
    const auto started = Clock::now();
    seconds_ = {};
    NewtonReport report;
    // every return hands the report its time breakdown
    const auto done = [&]() -> NewtonReport& {
      report.seconds = seconds_;
      report.seconds.total = std::chrono::duration<double>(Clock::now() - started).count();
      return report;
    };
    detail::require_positions("QuasistaticSolver::solve: x", x, n_);
    apply_boundary(x, boundary);
    detail::GradientTest test(options_.relative_tolerance, options_.absolute_tolerance, options_.reference_force);
    ForcingTerm forcing(*this);
    const double size = double((x.colwise().maxCoeff() - x.colwise().minCoeff()).norm());
    last_shift_ = 0;
    double accepted = std::numeric_limits<double>::quiet_NaN();  // the energy of the last accepted step's x
    double last_gnorm = 0;                 // ‖g‖ of the previous iteration (NewtonOptions::chord_below)
    // NewtonOptions::chord_first: the previous solve's last setup, made with these fixed DOFs
    const bool carried = setup_valid_ && options_.chord_first && setup_fixed_ == fixed_;
    for (Index it = 0;; ++it) {
      // the line search evaluated the energy at this x already (the same sum of the same terms:
      // the same bits), so an iteration after the first does not evaluate it again
      const double E = it == 0 ? timed(seconds_.energy, [&] { return total_energy(policy, x, terms...); }) : accepted;
      if (!std::isfinite(E)) throw ConvergenceError("quasistatic Newton (energy is not finite at iteration " + std::to_string(it) + ")", it, E);
      const double balance = timed(seconds_.gradient, [&] { return compute_gradient(policy, x, terms...); });
      const double gnorm = double(g_.norm());
      if (it == 0) report.initial_gradient_norm = gnorm;
      report.iterations = it;
      report.energy = E;
      report.gradient_norm = gnorm;
      if (test.converged(it, gnorm, balance)) {
        report.converged = true;
        return done();
      }
      if (it >= options_.max_iterations) {
        if (options_.accept_at_max_iterations) return done();
        throw ConvergenceError("quasistatic Newton", it, gnorm);
      }

      // Newton direction: H d = −g (fixed DOFs: identity rows, zero right-hand side).
      const double tolerance = test.threshold();
      forcing.set(it, gnorm, tolerance);
      rhs_ = -g_;
      bool projected = options_.hessian == NewtonOptions::Hessian::projected;
      LinearSolveInfo info;
      double slope = 0, shift = 0;
      const bool regularized = options_.hessian == NewtonOptions::Hessian::regularized;
      // after an iteration that needed τ > 10⁻³ the exact Hessian is not tried: the search starts at τ/10
      const bool warm = regularized && last_shift_ > 1e-3 * (1 + 1e-9);
      // the setup held now is the one a chord step would reuse; it counts as lost until this
      // iteration ends (a setup that throws part-way leaves the linear solver in no state to reuse)
      const bool reusable = setup_valid_;
      setup_valid_ = false;
      bool chord = reusable && (it == 0 ? carried : options_.chord_below > 0 && gnorm <= options_.chord_below * last_gnorm);
      if (chord) {
        // the previous iteration's matrix and setup (NewtonOptions::chord_below); a solve that does
        // not converge or does not descend makes this a full Newton iteration after all
        info = timed(seconds_.linear_solve, [&] { return linear_.solve(policy, rhs_, d_); });
        slope = double(g_.dot(d_));
        if (info.converged && slope < 0 && d_.allFinite()) {
          projected = setup_projected_;
          shift = setup_shift_;
        } else {
          chord = false;
          info = {.iterations = info.iterations};
        }
      }
      if (!chord && !projected) {
        if (warm) {
          assemble_hessian(policy, x, Definiteness::exact, terms...);
          projected = true;
        } else {
          projected = !newton_direction(policy, x, Definiteness::exact, info, terms...);
          if (!projected) {
            slope = double(g_.dot(d_));
            projected = !(slope < 0) || !d_.allFinite();
          }
        }
        if (projected && regularized) {
          shift = shifted_direction(policy, info, warm ? last_shift_ / 10 : 1e-3);
          if (shift > 0) {
            slope = double(g_.dot(d_));
            projected = false;
          }
        }
      }
      if (!chord) last_shift_ = shift;
      if (projected && !chord) {
        newton_direction(policy, x, Definiteness::project, info, terms...);
        slope = double(g_.dot(d_));
      }
      setup_valid_ = info.converged;
      setup_projected_ = projected;
      setup_shift_ = shift;
      if (!chord) setup_fixed_ = fixed_;
      last_gnorm = gnorm;
      if (!(slope < 0) || !d_.allFinite()) {  // still no descent (an unconverged iterative solve): fall back to −g
        d_ = -g_;
        slope = -double(g_.squaredNorm());
      } else if (info.converged && double(d_.cwiseAbs().maxCoeff()) <= options_.step_tolerance * size) {
        report.converged = true;
        return done();
      }

      // Backtracking on the total energy; differences below round-off of the terms' magnitudes
      // count as no increase, so the last steps of a converged solve are not rejected by noise.
      const double noise = 64 * std::numeric_limits<double>::epsilon() * magnitude_;
      double alpha = 1, trial_energy = 0;
      Index backtracks = 0;
      for (;; ++backtracks) {
        trial_ = x;
        Eigen::Map<VecX<S>>(trial_.data(), 3 * n_) += S(alpha) * d_;
        const double Et = timed(seconds_.energy, [&] { return total_energy(policy, trial_, terms...); });
        trial_energy = Et;
        if (std::isfinite(Et) && Et <= E + options_.armijo * alpha * slope + noise) break;
        if (backtracks >= options_.max_backtracks)
          throw ConvergenceError("quasistatic Newton (line search: no decrease along the Newton direction at iteration " + std::to_string(it) + ")",
                                 it, gnorm);
        alpha *= 0.5;
      }
      x.swap(trial_);
      accepted = trial_energy;
      report.linear_iterations += info.iterations;
      const NewtonIteration record{.iteration = it,
                                   .energy = E,
                                   .gradient_norm = gnorm,
                                   .step_length = alpha,
                                   .backtracks = backtracks,
                                   .linear_iterations = info.iterations,
                                   .linear_residual = info.relative_residual,
                                   .linear_tolerance = forcing.linear_tolerance(),
                                   .tolerance = tolerance,
                                   .projected = projected,
                                   .shift = shift,
                                   .chord = chord};
      report.history.push_back(record);
      if (options_.progress) options_.progress(record);
    }
  }

  /// NewtonOptions::forcing for the solve it lives in: sets the linear solver's tolerance per
  /// iteration and gives it back its own at the end (also when the solve throws).
  class ForcingTerm {
   public:
    explicit ForcingTerm(QuasistaticSolver& s) : s_(s) {
      if constexpr (kTunable) own_ = s_.linear_.options().tolerance;
    }
    ~ForcingTerm() {
      if constexpr (kTunable) s_.linear_.options().tolerance = own_;
    }
    ForcingTerm(const ForcingTerm&) = delete;
    ForcingTerm& operator=(const ForcingTerm&) = delete;
    /// The tolerance of iteration `it`, whose gradient norm is `gnorm`; `converged_below` is the
    /// gradient norm that counts as converged (the safeguard's τ).
    void set(Index it, double gnorm, double converged_below) {
      if constexpr (kTunable) {
        if (s_.options_.forcing != NewtonOptions::Forcing::adaptive) return;
        const double cap = std::max(own_, s_.options_.forcing_max);
        double eta = cap;
        if (it > 0 && last_norm_ > 0) {
          const double ratio = gnorm / last_norm_;
          eta = 0.9 * ratio * ratio;
          const double safeguard = 0.9 * last_eta_ * last_eta_;
          if (safeguard > 0.1) eta = std::max(eta, safeguard);
        }
        if (s_.options_.forcing_safeguard && gnorm > 0) eta = std::max(eta, 0.5 * converged_below / gnorm);
        eta = std::clamp(eta, own_, cap);
        s_.linear_.options().tolerance = eta;
        last_eta_ = eta;
        last_norm_ = gnorm;
      }
    }

    /// The linear solver's relative tolerance now (0 for a solver without one).
    double linear_tolerance() const {
      if constexpr (kTunable)
        return s_.linear_.options().tolerance;
      else
        return 0;
    }

   private:
    static constexpr bool kTunable = requires(Linear& l) { l.options().tolerance = 0.1; };
    QuasistaticSolver& s_;
    double own_ = 0, last_eta_ = 0, last_norm_ = 0;
  };

  /// Σ terms' energies at x (J).
  template <class P, class... Terms>
  double total_energy(P policy, const Points<S>& x, const Terms&... terms) {
    return detail::total_energy(policy, x, magnitude_, terms...);
  }

  /// Sets g_ to ∂E/∂x over the free DOFs and returns the forces' scale (detail/term_sums.hpp).
  template <class P, class... Terms>
  double compute_gradient(P policy, const Points<S>& x, const Terms&... terms) {
    return detail::free_gradient(policy, x, fixed_, term_grad_, g_, terms...);
  }
  void apply_boundary(Points<S>& x, const DirichletBoundary<S>& b) { detail::apply_dirichlet("QuasistaticSolver", x, b, fixed_); }

  /// Assembles the Hessian (every term with definiteness `d`, in the order given) and solves
  /// H d = rhs_. False when the system turned out not positive definite.
  template <class P, class... Terms>
  bool newton_direction(P policy, const Points<S>& x, Definiteness d, LinearSolveInfo& info, const Terms&... terms) {
    const SparseMatrix<S>& A = assemble_hessian(policy, x, d, terms...);
    try {
      timed(seconds_.linear_setup, [&] { linear_.compute(policy, A, H_.pattern_version()); });
    } catch (const ConvergenceError&) {
      if (d == Definiteness::project) throw;
      return false;
    }
    if constexpr (requires { linear_.positive_definite(); })
      if (d == Definiteness::exact && !linear_.positive_definite()) return false;
    const LinearSolveInfo one = timed(seconds_.linear_solve, [&] { return linear_.solve(policy, rhs_, d_); });
    info.iterations += one.iterations;
    info.relative_residual = one.relative_residual;
    info.converged = one.converged;
    return one.converged || d == Definiteness::project;
  }

  /// Every term's Hessian blocks at x (definiteness d) into H_, assembled over the free DOFs.
  template <class P, class... Terms>
  const SparseMatrix<S>& assemble_hessian(P policy, const Points<S>& x, Definiteness d, const Terms&... terms) {
    return timed(seconds_.hessian, [&]() -> const SparseMatrix<S>& {
      H_.set_zero();
      (terms.add_hessian(policy, x, H_, d), ...);
      return H_.assemble(policy, fixed_);
    });
  }

  /// Hessian::regularized: with the exact Hessian H (the matrix H_ last assembled) not positive
  /// definite, solves (H + τ m I) d = rhs_ for τ = first, 10·first, … ≤ 10², the first that
  /// factors and descends. Returns that τ, or 0 when none did (the caller then projects).
  template <class P>
  double shifted_direction(P policy, LinearSolveInfo& info, double first) {
    const SparseMatrix<S>& A = H_.assembled();
    shifted_ = A;  // the same pattern: its storage is reused after the first call
    shifted_diagonal_.clear();
    double m = 0;
    for (Index i = 0; i < A.rows(); ++i) {  // the stored diagonal entries (no insertion: the pointers stay valid)
      if (fixed_[std::size_t(i)]) continue;
      const auto* begin = shifted_.innerIndexPtr() + shifted_.outerIndexPtr()[i];
      const auto* end = shifted_.innerIndexPtr() + shifted_.outerIndexPtr()[i + 1];
      const auto* at = std::lower_bound(begin, end, i);
      if (at == end || *at != i) continue;
      S* a = shifted_.valuePtr() + (at - shifted_.innerIndexPtr());
      shifted_diagonal_.push_back({a, *a});
      m += std::abs(double(*a));
    }
    if (shifted_diagonal_.empty() || !(m > 0)) return 0;
    m /= double(shifted_diagonal_.size());
    for (double tau = first; tau <= 1e2 * (1 + 1e-9); tau *= 10) {
      for (auto& [entry, exact] : shifted_diagonal_) *entry = exact + S(tau * m);
      try {
        timed(seconds_.linear_setup, [&] { linear_.compute(policy, shifted_, H_.pattern_version()); });
      } catch (const ConvergenceError&) {
        continue;
      }
      if constexpr (requires { linear_.positive_definite(); })
        if (!linear_.positive_definite()) continue;
      const LinearSolveInfo one = timed(seconds_.linear_solve, [&] { return linear_.solve(policy, rhs_, d_); });
      info.iterations += one.iterations;
      info.relative_residual = one.relative_residual;
      info.converged = one.converged;
      if (one.converged && d_.allFinite() && double(g_.dot(d_)) < 0) return tau;
    }
    return 0;
  }

  using Clock = std::chrono::steady_clock;
  /// f(), its wall time added to `seconds` (also when it throws).
  template <class F>
  static decltype(auto) timed(double& seconds, F&& f) {
    struct Add {
      double& to;
      Clock::time_point from = Clock::now();
      ~Add() { to += std::chrono::duration<double>(Clock::now() - from).count(); }
    } add{seconds};
    return f();
  }

  Index n_;
  NewtonOptions options_;
  NewtonSeconds seconds_;  ///< the running solve's breakdown (NewtonReport::seconds)
  Linear linear_;
  BlockHessian<S> H_;
  std::vector<char> fixed_;
  Points<S> term_grad_, trial_;
  VecX<S> g_, rhs_, d_;
  SparseMatrix<S> shifted_;  ///< Hessian::regularized's H + τ m I (kept: its storage is reused)
  std::vector<std::pair<S*, S>> shifted_diagonal_;  ///< its free diagonal entries and their exact values
  double magnitude_ = 0;
  double last_shift_ = 0;  ///< Hessian::regularized: the τ of the last iteration (0: unshifted), reset by each solve
  // The linear solver's current setup, for chord steps (NewtonOptions::chord_below, chord_first):
  bool setup_valid_ = false;       ///< it holds a setup whose solve converged, and nothing threw since
  bool setup_projected_ = false;   ///< made from the projected Hessian
  double setup_shift_ = 0;         ///< made from H + τ m I with this τ (Hessian::regularized; 0: none)
  std::vector<char> setup_fixed_;  ///< with these fixed DOFs (identity rows)
};

}  // namespace simsr::physics
