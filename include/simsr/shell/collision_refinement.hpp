#pragma once
/// \file
/// Collision refinement of a synthesized cloth (Chen et al. 2023, supplement §2, after Wang et al.
/// 2019 [WSFM19]; issue #14 item 4). The network never sees the obstacle, so a synthesized fine
/// cloth may dip into it. Each vertex found inside is given a target: its closest point on the
/// obstacle's surface pushed out along the normal by `clearance`. Then the cloth is deformed to
///
///     min_x  Σ_{i∈C} w_i ‖x_i − p_i‖²  +  Σ_i A_i ‖(M⁻¹L(x − x₀))_i‖²  +  Σ_i A_i ‖x_i − x₀_i‖² / ℓ⁴
///
/// (L the cotangent Laplacian of the rest mesh, M its Voronoi areas A_i, x₀ the synthesized cloth):
/// the Laplacian of x₀, its wrinkles, is kept while the constrained vertices move out, and the
/// distance term (WSFM19's "Euclidean distance") keeps the rest in place beyond about ℓ =
/// `falloff` (m), at any resolution (both terms are integrals over the surface). w_i is
/// `weight` × the rest of the system's diagonal at i: the targets are met to about 1/weight.
/// Vertices found inside after a solve join C (their targets taken there) and it is solved again,
/// at most `max_iterations` times. Whatever is still inside after the last solve is projected onto
/// its target, so no vertex is left inside (the report counts these projections: 0 in the usual
/// case).
///
///     shell::CollisionRefinement refine(fine_rest);
///     const auto report = refine.refine(exec::seq, obstacle, x);   // x: in/out, #V×3
///
/// Every solve's matrix is the same sparse pattern (only some diagonal entries grow), so its
/// linear solver (a physics::LinearSolver: SparseCholesky, Eigen's simplicial LDLᵀ, by default;
/// physics::CholmodCholesky built with CHOLMOD) analyses it once and refactors per solve. The
/// factorization is nearly all of a refinement: benchmarks/bench_shell.cpp measures the two.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../mesh/cotangent_laplacian.hpp"
#include "../mesh/tri_mesh.hpp"
#include "../mesh/vertex_areas.hpp"
#include "../physics/forces/obstacle_contact.hpp"
#include "../physics/hessian.hpp"
#include "../physics/linear_solvers/linear_solver.hpp"
#include "../physics/linear_solvers/sparse_cholesky.hpp"

namespace simsr::shell {

struct CollisionRefinementOptions {
  double clearance = 2e-3;    ///< m: targets this far outside the obstacle's surface
  double falloff = 0.1;       ///< ℓ (m): how far around a pushed-out patch the cloth follows it
  double weight = 1e4;        ///< the targets' weight relative to the other terms' at the vertex
  Index max_iterations = 3;   ///< solves (the supplement's "≤ 3")
};

struct CollisionRefinementReport {
  Index inside_before = 0;  ///< vertices inside the obstacle on entry
  Index solves = 0;         ///< Laplacian solves taken (0 when nothing was inside)
  Index constrained = 0;    ///< vertices with a target in the last solve
  Index projected = 0;      ///< still inside after the last solve, projected onto their targets
  double deepest_before = 0, deepest_after = 0;  ///< the most negative distance (m; 0: none inside)
};

/// The refinement of the file comment, for one rest mesh (its Laplacian built once), solved by
/// `Linear`. A Linear that is not a physics::LinearSolver stops the build with one sentence.
template <class Linear = physics::SparseCholesky<>>
class CollisionRefinement {
  static_assert(physics::assert_linear_solver<Linear>());

 public:
  /// MeshError for a bad triangle; ArgumentError for a bad option.
  explicit CollisionRefinement(const TriMesh<>& rest, CollisionRefinementOptions options = {}) : options_(options) {
    if (!(options_.clearance >= 0) || !std::isfinite(options_.clearance)) throw ArgumentError("CollisionRefinement: clearance must be finite and >= 0");
    if (!(options_.weight > 0) || !std::isfinite(options_.weight)) throw ArgumentError("CollisionRefinement: weight must be finite and > 0");
    if (!(options_.falloff > 0) || !std::isfinite(options_.falloff)) throw ArgumentError("CollisionRefinement: falloff must be finite and > 0");
    if (options_.max_iterations < 1) throw ArgumentError("CollisionRefinement: max_iterations must be >= 1");
    for (Index f = 0; f < rest.F.rows(); ++f)
      for (int k = 0; k < 3; ++k)
        if (rest.F(f, k) < 0 || rest.F(f, k) >= rest.V.rows())
          throw MeshError("triangle", f, "CollisionRefinement: vertex " + std::to_string(rest.F(f, k)) + " outside [0, " + std::to_string(rest.V.rows()) + ")");
    const Eigen::SparseMatrix<double> L = cotangent_laplacian(exec::seq, rest.V, rest.F);
    const VecX<> areas = voronoi_areas(rest.V, rest.F);
    for (Index i = 0; i < areas.size(); ++i)
      if (!(areas[i] > 0)) throw MeshError("vertex", i, "CollisionRefinement: zero Voronoi area (every triangle at it degenerate or none)");
    const VecX<> inv_area = areas.cwiseInverse(), position = areas / std::pow(options_.falloff, 4);
    Eigen::SparseMatrix<double> A(L.transpose() * inv_area.asDiagonal() * L);
    for (Index i = 0; i < A.rows(); ++i) A.coeffRef(i, i) += position[i];
    A_ = physics::SparseMatrix<double>(A);
    A_.makeCompressed();
    K_ = A_;
    const Index n = A_.rows();
    diagonal_.resize(std::size_t(n));  // where each row's diagonal entry sits in the values
    for (Index i = 0; i < n; ++i)
      for (Index k = A_.outerIndexPtr()[i]; k < A_.outerIndexPtr()[i + 1]; ++k)
        if (A_.innerIndexPtr()[k] == i) diagonal_[std::size_t(i)] = k;
    target_weight_.resize(n);
    for (Index i = 0; i < n; ++i) target_weight_[i] = options_.weight * A_.valuePtr()[diagonal_[std::size_t(i)]];
    // the per-frame buffers, sized once
    constrained_.assign(std::size_t(n), 0);
    target_.resize(n, 3);
    kept_.resize(n, 3);
    b_.resize(n);
    xc_.resize(n);
  }

  Index num_vertices() const { return A_.rows(); }
  /// LᵀM⁻¹L + M/ℓ⁴: the matrix of every solve before the targets' weights join its diagonal.
  const physics::SparseMatrix<double>& system_matrix() const { return A_; }

  /// Refines x (#V×3, in/out) against `obstacle` (see the file comment). ShapeError for another
  /// vertex count; ArgumentError for a non-finite position. One call at a time per object (the
  /// factorization is kept between calls).
  template <exec::HostPolicy P, physics::Obstacle O>
  CollisionRefinementReport refine(P policy, const O& obstacle, Points<>& x) {
    if (x.rows() != num_vertices() || x.cols() != 3)
      throw ShapeError("CollisionRefinement::refine: positions", {num_vertices(), 3}, {x.rows(), x.cols()});
    if (!x.allFinite()) throw ArgumentError("CollisionRefinement::refine: a position is not finite");
    CollisionRefinementReport report;
    const Index n = num_vertices();
    std::vector<char>& constrained = constrained_;
    Points<>& target = target_;
    std::fill(constrained.begin(), constrained.end(), 0);
    auto inside = [&](Index i, double& d) {
      d = obstacle.distance(Vec3<>(x.row(i).transpose()));
      return d < 0;
    };
    auto take_target = [&](Index i, double d) {
      const Vec3<> p = x.row(i).transpose(), nrm = obstacle.distance_gradient(p);
      target.row(i) = (p + (options_.clearance - d) * nrm).transpose();  // d < 0: out by |d| + clearance
      constrained[std::size_t(i)] = 1;
    };
    for (Index i = 0; i < n; ++i) {
      double d;
      if (inside(i, d)) {
        ++report.inside_before;
        report.deepest_before = std::min(report.deepest_before, d);
        take_target(i, d);
      }
    }
    if (report.inside_before == 0) return report;
    kept_.noalias() = A_ * x;  // the Laplacian and distance terms' right-hand side at x₀
    for (Index it = 0; it < options_.max_iterations; ++it) {
      // K = A_ with the constrained vertices' weights on the diagonal: A_'s pattern, analysed by
      // the solver at the first solve and kept (pattern version 1 for good)
      std::copy(A_.valuePtr(), A_.valuePtr() + A_.nonZeros(), K_.valuePtr());
      for (Index i = 0; i < n; ++i)
        if (constrained[std::size_t(i)]) K_.valuePtr()[diagonal_[std::size_t(i)]] += target_weight_[i];
      solver_.compute(policy, K_, 1);
      for (int c = 0; c < 3; ++c) {
        for (Index i = 0; i < n; ++i) b_[i] = kept_(i, c) + (constrained[std::size_t(i)] ? target_weight_[i] * target(i, c) : 0.0);
        const physics::LinearSolveInfo info = solver_.solve(policy, b_, xc_);
        if (!info.converged) throw ConvergenceError("CollisionRefinement: the Laplacian system", info.iterations, info.relative_residual);
        x.col(c) = xc_;
      }
      ++report.solves;
      bool any = false;
      for (Index i = 0; i < n; ++i) {
        double d;
        if (inside(i, d)) {
          any = true;
          if (!constrained[std::size_t(i)]) take_target(i, d);
        }
      }
      if (!any) break;
    }
    for (Index i = 0; i < n; ++i) report.constrained += constrained[std::size_t(i)];
    for (Index i = 0; i < n; ++i) {
      double d;
      if (inside(i, d)) {  // short of its target (the finite weight) or new: out along the normal from here
        take_target(i, d);
        x.row(i) = target.row(i);
        ++report.projected;
      }
    }
    for (Index i = 0; i < n; ++i) report.deepest_after = std::min(report.deepest_after, obstacle.distance(Vec3<>(x.row(i).transpose())));
    return report;
  }

 private:
  CollisionRefinementOptions options_;
  physics::SparseMatrix<double> A_;  ///< LᵀM⁻¹L + M/ℓ⁴
  physics::SparseMatrix<double> K_;  ///< one solve's matrix (A_'s pattern)
  std::vector<Index> diagonal_;      ///< per row, the index of its diagonal entry in A_'s (and K_'s) values
  VecX<> target_weight_;             ///< w_i = weight × A_ii
  Linear solver_;                    ///< analyses K_'s pattern once, factors it per solve
  // one frame's state, kept to reuse the memory: constrained vertices, their targets, A_ x₀, one column's rhs and solution
  std::vector<char> constrained_;
  Points<> target_, kept_;
  VecX<> b_, xc_;
};

}  // namespace simsr::shell
