#pragma once
/// \file
/// Exact dense rectangular linear assignment: the shortest augmenting path algorithm of Crouse
/// (2016), the one behind scipy.optimize.linear_sum_assignment, used by Park et al. (2023, §3.2)
/// to map LR vertices one-to-one onto HR surface vertices.
///
///     Eigen::MatrixXd C = ...;                                 // N×M, N ≤ M
///     auto a = simsr::neighbors::linear_assignment(C);
///     // a.row_to_col[i]: the column of row i (all distinct); a.total_cost = Σ C(i, a.row_to_col[i])
///
/// O(N²M) time and O(N + M) extra memory: for small inputs (a few thousand rows). The paper's
/// 15,872 × 35,637 needs the sparse solver (sparse_assignment.hpp, point_assignment.hpp).

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/types.hpp"

namespace simsr::neighbors {

/// An optimal assignment of N rows to N distinct columns, with the dual solution that proves it:
/// u_i + v_j ≤ C(i,j) everywhere, equality on the assigned pairs, v_j ≤ 0, and v_j = 0 on the
/// M − N unassigned columns (the LP dual of "each row exactly once, each column at most once").
struct Assignment {
  IndexVector row_to_col;  ///< N: column of each row
  IndexVector col_to_row;  ///< M: row of each column, −1 when unassigned
  double total_cost = 0;   ///< Σ_i C(i, row_to_col[i]), summed in row order from the input costs
  VecX<double> row_dual;   ///< N: u
  VecX<double> col_dual;   ///< M: v

  /// Sizes for `rows` × `cols`: nothing assigned, zero duals (the solvers' starting point).
  void reset(Index rows, Index cols) {
    row_to_col = IndexVector::Constant(rows, -1);
    col_to_row = IndexVector::Constant(cols, -1);
    row_dual = VecX<double>::Zero(rows);
    col_dual = VecX<double>::Zero(cols);
    total_cost = 0;
  }
};

/// Minimum-cost assignment of every row of the N×M cost matrix C (N ≤ M) to a distinct column.
/// Entries may be negative; +inf marks a forbidden pair. Ties are broken exactly as scipy's
/// implementation does (same scan order), so the two return the same columns.
/// Throws ShapeError when N > M (pass the transpose), ArgumentError for a NaN or −inf entry
/// (naming it) and when no assignment avoids the +inf entries (naming the row that cannot be
/// placed). O(N²M); pass a row-major double matrix to avoid a copy.
template <class Derived>
Assignment linear_assignment(const Eigen::MatrixBase<Derived>& C) {
  const Index nr = C.rows(), nc = C.cols();
  if (nr > nc)
    throw ShapeError("linear_assignment: cost matrix (rows ≤ columns; pass the transpose)", {nc, nc}, {nr, nc});
  // Rows are scanned contiguously: a row-major double input is used in place, anything else copied once.
  using RowMajorCosts = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Ref<const RowMajorCosts> cost(C.template cast<double>());
  for (Index i = 0; i < nr; ++i)
    for (Index j = 0; j < nc; ++j) {
      const double c = cost(i, j);
      if (std::isnan(c) || c == -std::numeric_limits<double>::infinity())
        throw ArgumentError("linear_assignment: cost(" + std::to_string(i) + ", " + std::to_string(j) + ") is " +
                            (std::isnan(c) ? "NaN" : "-inf") + "; costs must be finite or +inf (forbidden)");
    }

  constexpr double inf = std::numeric_limits<double>::infinity();
  Assignment a;
  a.reset(nr, nc);
  auto& u = a.row_dual;
  auto& v = a.col_dual;
  auto& col4row = a.row_to_col;
  auto& row4col = a.col_to_row;

  std::vector<VIndex> path(static_cast<std::size_t>(nc), -1);
  std::vector<VIndex> remaining(static_cast<std::size_t>(nc));
  std::vector<double> spc(static_cast<std::size_t>(nc));  // shortest path cost to each column
  std::vector<char> scanned_row(static_cast<std::size_t>(nr)), scanned_col(static_cast<std::size_t>(nc));

  for (Index cur = 0; cur < nr; ++cur) {
    // Dijkstra over reduced costs C − u − v from row `cur` to the nearest unassigned column.
    double min_val = 0;
    Index num_remaining = nc;
    for (Index it = 0; it < nc; ++it) remaining[it] = static_cast<VIndex>(nc - it - 1);
    std::fill(scanned_row.begin(), scanned_row.end(), 0);
    std::fill(scanned_col.begin(), scanned_col.end(), 0);
    std::fill(spc.begin(), spc.end(), inf);
    Index i = cur, sink = -1;
    while (sink < 0) {
      scanned_row[i] = 1;
      Index index = -1;
      double lowest = inf;
      for (Index it = 0; it < num_remaining; ++it) {
        const Index j = remaining[it];
        const double r = min_val + cost(i, j) - u[i] - v[j];
        if (r < spc[j]) {
          path[j] = static_cast<VIndex>(i);
          spc[j] = r;
        }
        if (spc[j] < lowest || (spc[j] == lowest && row4col[j] == -1)) {
          lowest = spc[j];
          index = it;
        }
      }
      min_val = lowest;
      if (min_val == inf)
        throw ArgumentError("linear_assignment: infeasible: row " + std::to_string(cur) +
                            " cannot be given a column of finite cost distinct from rows 0.." +
                            std::to_string(cur - 1) + " (too many +inf entries)");
      const Index j = remaining[index];
      if (row4col[j] == -1)
        sink = j;
      else
        i = row4col[j];
      scanned_col[j] = 1;
      remaining[index] = remaining[--num_remaining];
    }
    u[cur] += min_val;
    for (Index r = 0; r < nr; ++r)
      if (scanned_row[r] && r != cur) u[r] += min_val - spc[col4row[r]];
    for (Index j = 0; j < nc; ++j)
      if (scanned_col[j]) v[j] -= min_val - spc[j];
    for (Index j = sink;;) {
      const Index r = path[j];
      row4col[j] = static_cast<VIndex>(r);
      const Index prev = col4row[r];
      col4row[r] = static_cast<VIndex>(j);
      if (r == cur) break;
      j = prev;
    }
  }
  for (Index r = 0; r < nr; ++r) a.total_cost += cost(r, col4row[r]);
  return a;
}

}  // namespace simsr::neighbors
