#pragma once
/// \file
/// One-to-one assignment of N points onto M ≥ N points minimizing the total Euclidean distance
/// (Park et al. 2023, §3.2: LR vertices onto HR surface vertices), at the paper's 15,872 × 35,637.
///
///     auto a = simsr::neighbors::assign_points(simsr::exec::omp, lr_vertices, hr_vertices);
///     // a.row_to_col[i] = HR vertex of LR vertex i; a.globally_optimal: proven optimal over all N·M pairs
///
/// Method: candidate edges from each point's k nearest targets (kd-tree), solved exactly by
/// sparse_assignment. Two things can go wrong with a candidate graph, and both are repaired by
/// giving more candidates (k doubled, up to M) only to the rows concerned, then re-solving:
///  - no complete matching (Hall's condition fails): the rows of the failing search grow;
///  - the candidate optimum is not provably the global one. Proof used: with v ≤ 0, the duals are
///    feasible for every non-candidate pair (i, j) as soon as u_i ≤ r_i, the distance to row i's
///    farthest candidate (every non-candidate is at least that far), so the LP optimality
///    conditions hold on the complete N×M problem. Rows with u_i > r_i grow.
/// Each round is recorded in `log`.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "detail/assignment_knn.hpp"
#include "sparse_assignment.hpp"

namespace simsr::neighbors {

/// Parameters of assign_points.
struct PointAssignmentOptions {
  Index k = 16;               ///< initial candidates per point (clamped to M)
  Index max_rounds = 40;      ///< candidate growth rounds before giving up (ConvergenceError)
  bool prove_global = true;   ///< grow candidates until the global certificate holds
};

/// Result of assign_points.
struct PointAssignment {
  IndexVector row_to_col;              ///< N: target of each point (distinct)
  double total_cost = 0;               ///< Σ_i |from_i − to_{row_to_col[i]}|
  VecX<double> row_dual, col_dual;     ///< the certificate's duals (N, M)
  AssignmentCertificate certificate;   ///< optimality on the final candidate graph
  bool globally_optimal = false;       ///< u_i ≤ r_i (or all M candidates) for every row
  Index uncertified_rows = 0;          ///< rows where that bound failed (0 when globally_optimal)
  Index rounds = 0;                    ///< sparse solves run
  Index candidate_edges = 0;           ///< edges of the final candidate graph
  Index min_k = 0, max_k = 0;          ///< final candidates per row
  Index greedy_rows = 0, augmentations = 0;  ///< of the final solve
  std::vector<std::string> log;        ///< one line per round
};

/// Minimum total Euclidean distance one-to-one assignment of `from` (N×3) onto `to` (M×3),
/// N ≤ M. The kd-tree queries run under `policy`; the solve itself is sequential, so seq and omp
/// give identical results. Throws ShapeError (not N×3 / M×3, or N > M), ArgumentError (non-finite
/// coordinate, k < 1), ConvergenceError after `max_rounds` rounds.
template <exec::HostPolicy Policy, class DA, class DB>
PointAssignment assign_points(Policy policy, const Eigen::MatrixBase<DA>& from, const Eigen::MatrixBase<DB>& to,
                              const PointAssignmentOptions& options = {}) {
  const Index n = from.rows(), m = to.rows();
  if (from.cols() != 3) throw ShapeError("assign_points: from", {-1, 3}, {from.rows(), from.cols()});
  if (to.cols() != 3) throw ShapeError("assign_points: to", {-1, 3}, {to.rows(), to.cols()});
  if (n > m) throw ShapeError("assign_points: from (no more points than targets)", {m, 3}, {n, 3});
  if (options.k < 1) throw ArgumentError("assign_points: k = " + std::to_string(options.k) + " must be at least 1");
  for (Index i = 0; i < n; ++i)
    for (Index d = 0; d < 3; ++d)
      if (!std::isfinite(double(from(i, d))))
        throw ArgumentError("assign_points: from row " + std::to_string(i) + " holds a non-finite coordinate");
  for (Index i = 0; i < m; ++i)
    for (Index d = 0; d < 3; ++d)
      if (!std::isfinite(double(to(i, d))))
        throw ArgumentError("assign_points: to row " + std::to_string(i) + " holds a non-finite coordinate");

  PointAssignment out;
  if (n == 0) {
    out.globally_optimal = true;
    out.col_dual = VecX<double>::Zero(m);
    return out;
  }
  const Points<double> A = from.template cast<double>();
  const Points<double> B = to.template cast<double>();
  const detail::AssignmentKdTree tree(B);

  std::vector<Index> k(static_cast<std::size_t>(n), std::min(options.k, m));
  std::vector<std::vector<VIndex>> cand(static_cast<std::size_t>(n));
  std::vector<double> radius(static_cast<std::size_t>(n), 0.0);
  std::vector<char> stale(static_cast<std::size_t>(n), 1);

  for (out.rounds = 1; out.rounds <= options.max_rounds; ++out.rounds) {
    // Candidates of the rows whose k changed (all of them in round 1).
    exec::parallel_for(policy, n, [&](Index i) {
      if (!stale[i]) return;
      thread_local std::vector<std::size_t> idx;
      thread_local std::vector<double> d2;
      const double q[3] = {A(i, 0), A(i, 1), A(i, 2)};
      tree.knn(q, k[i], idx, d2);
      auto& c = cand[i];
      c.assign(idx.begin(), idx.end());
      std::sort(c.begin(), c.end());
      double r = 0;
      for (const VIndex j : c) r = std::max(r, detail::assignment_distance(A, i, B, j));
      radius[i] = r;
      stale[i] = 0;
    });
    SparseCostGraph g(n, m);
    for (Index i = 0; i < n; ++i) {
      for (const VIndex j : cand[i]) g.add(j, detail::assignment_distance(A, i, B, j));
      g.end_row();
    }
    const SparseAssignment s = sparse_assignment(g);
    const auto [kmin, kmax] = std::minmax_element(k.begin(), k.end());
    const std::string head = "round " + std::to_string(out.rounds) + ": k " + std::to_string(*kmin) + ".." +
                             std::to_string(*kmax) + ", " + std::to_string(g.num_edges()) + " edges: ";
    if (!s.feasible) {
      for (const VIndex i : s.hall_rows) k[i] = std::min(2 * k[i], m), stale[i] = 1;
      out.log.push_back(head + "no complete matching; " + std::to_string(s.hall_rows.size()) +
                        " rows in the violated Hall set get twice the candidates");
      continue;
    }
    const AssignmentCertificate cert = certify(g, s);
    std::vector<VIndex> grow;
    for (Index i = 0; i < n; ++i)
      if (k[i] < m && s.row_dual[i] > radius[i] + cert.tolerance) grow.push_back(static_cast<VIndex>(i));
    out.row_to_col = s.row_to_col;
    out.total_cost = s.total_cost;
    out.row_dual = s.row_dual;
    out.col_dual = s.col_dual;
    out.certificate = cert;
    out.uncertified_rows = static_cast<Index>(grow.size());
    out.globally_optimal = grow.empty() && cert.optimal;
    out.candidate_edges = g.num_edges();
    out.min_k = *kmin, out.max_k = *kmax;
    out.greedy_rows = s.greedy_rows, out.augmentations = s.augmentations;
    out.log.push_back(head + "optimal on candidates (cost " + std::to_string(s.total_cost) + ", " +
                      std::to_string(s.greedy_rows) + " greedy rows, " + std::to_string(s.augmentations) +
                      " augmentations); " +
                      (grow.empty() ? std::string("global certificate holds")
                                    : std::to_string(grow.size()) + " rows lack the global certificate"));
    if (grow.empty() || !options.prove_global) return out;
    for (const VIndex i : grow) k[i] = std::min(2 * k[i], m), stale[i] = 1;
  }
  throw ConvergenceError("assign_points (candidate growth)", options.max_rounds, double(out.uncertified_rows));
}

}  // namespace simsr::neighbors
