#include <doctest/doctest.h>

#include <simsr/neighbors/linear_assignment.hpp>
#include <simsr/neighbors/point_assignment.hpp>
#include <simsr/neighbors/sparse_assignment.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <set>

using namespace simsr;
using namespace simsr::neighbors;

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

/// Optimum by enumerating every injective row → column map (tiny N, M only).
double brute_force_optimum(const Eigen::MatrixXd& C) {
  const Index n = C.rows(), m = C.cols();
  std::vector<Index> cols(static_cast<std::size_t>(m));
  std::iota(cols.begin(), cols.end(), 0);
  double best = inf;
  // Every permutation of the columns; its first n entries are an injective map.
  do {
    double s = 0;
    for (Index i = 0; i < n; ++i) s += C(i, cols[i]);
    best = std::min(best, s);
  } while (std::next_permutation(cols.begin(), cols.end()));
  return best;
}

void check_is_assignment(const IndexVector& r2c, Index m) {
  std::set<VIndex> used;
  for (Index i = 0; i < r2c.size(); ++i) {
    REQUIRE(r2c[i] >= 0);
    REQUIRE(r2c[i] < m);
    used.insert(r2c[i]);
  }
  CHECK(Index(used.size()) == r2c.size());
}

/// The LP optimality conditions of a dense assignment, checked independently of the solver.
void check_dense_duals(const Eigen::MatrixXd& C, const Assignment& a) {
  const double tol = 1e-9 * (1 + C.cwiseAbs().unaryExpr([](double x) { return std::isfinite(x) ? x : 0.0; }).maxCoeff());
  for (Index i = 0; i < C.rows(); ++i)
    for (Index j = 0; j < C.cols(); ++j) {
      if (!std::isfinite(C(i, j))) continue;
      CHECK(a.row_dual[i] + a.col_dual[j] <= C(i, j) + tol);
    }
  for (Index i = 0; i < C.rows(); ++i) CHECK(std::abs(a.row_dual[i] + a.col_dual[a.row_to_col[i]] - C(i, a.row_to_col[i])) <= tol);
  for (Index j = 0; j < C.cols(); ++j) {
    CHECK(a.col_dual[j] <= tol);
    if (a.col_to_row[j] < 0) CHECK(a.col_dual[j] == 0.0);
  }
}

SparseCostGraph full_graph(const Eigen::MatrixXd& C) {
  SparseCostGraph g(C.rows(), C.cols());
  for (Index i = 0; i < C.rows(); ++i) {
    for (Index j = 0; j < C.cols(); ++j)
      if (std::isfinite(C(i, j))) g.add(j, C(i, j));
    g.end_row();
  }
  return g;
}

/// Points in a few tight clusters, some duplicated exactly (equal costs everywhere).
Points<> clustered_points(Index n, int clusters, std::mt19937& rng, bool duplicates) {
  std::normal_distribution<double> g(0, 1);
  Points<> c(clusters, 3);
  for (Index i = 0; i < c.size(); ++i) c.data()[i] = 10 * g(rng);
  Points<> P(n, 3);
  for (Index i = 0; i < n; ++i) {
    const Index k = i % clusters;
    for (int d = 0; d < 3; ++d) P(i, d) = c(k, d) + 0.3 * g(rng);
    if (duplicates && i > 0 && i % 5 == 0) P.row(i) = P.row(i - 1);
  }
  return P;
}

Eigen::MatrixXd distance_matrix(const Points<>& A, const Points<>& B) {
  Eigen::MatrixXd C(A.rows(), B.rows());
  for (Index i = 0; i < A.rows(); ++i)
    for (Index j = 0; j < B.rows(); ++j) C(i, j) = neighbors::detail::assignment_distance(A, i, B, j);
  return C;
}

}  // namespace

TEST_CASE("linear_assignment: scipy's documented example and a rectangular case") {
  Eigen::MatrixXd C(3, 3);
  C << 4, 1, 3, 2, 0, 5, 3, 2, 2;
  const auto a = linear_assignment(C);
  CHECK(a.row_to_col == (IndexVector(3) << 1, 0, 2).finished());
  CHECK(a.total_cost == 5.0);
  check_dense_duals(C, a);

  Eigen::MatrixXd R(2, 4);  // row 0 prefers column 3, row 1 too: row 1 must settle for column 0
  R << 9, 9, 9, 1, 2, 9, 9, 1.5;
  const auto b = linear_assignment(R);
  CHECK(b.row_to_col == (IndexVector(2) << 3, 0).finished());
  CHECK(b.total_cost == 3.0);
  CHECK(b.col_to_row == (IndexVector(4) << 1, -1, -1, 0).finished());
}

TEST_CASE("linear_assignment: optimal against enumeration on random rectangular matrices, ties, negatives, +inf") {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 300; ++trial) {
    const Index n = 1 + trial % 4, m = n + (trial / 4) % 3;
    Eigen::MatrixXd C(n, m);
    std::uniform_int_distribution<int> small(-3, 3);  // many exact ties
    std::uniform_real_distribution<double> real(-1, 2);
    for (Index i = 0; i < C.size(); ++i) C.data()[i] = trial % 2 ? small(rng) : real(rng);
    if (trial % 3 == 0)  // forbid some pairs, keeping the diagonal so a finite assignment exists
      for (Index i = 0; i < n; ++i)
        for (Index j = 0; j < m; ++j)
          if (i != j && (i + j + trial) % 3 == 0) C(i, j) = inf;
    CAPTURE(C);
    const auto a = linear_assignment(C);
    check_is_assignment(a.row_to_col, m);
    const double best = brute_force_optimum(C);
    if (trial % 2)
      CHECK(a.total_cost == best);  // integers: exact
    else
      CHECK(a.total_cost == doctest::Approx(best).epsilon(1e-13));
    check_dense_duals(C, a);
  }
}

TEST_CASE("linear_assignment: errors name the problem") {
  CHECK_THROWS_AS(linear_assignment(Eigen::MatrixXd::Zero(3, 2)), ShapeError);
  Eigen::MatrixXd C = Eigen::MatrixXd::Ones(2, 3);
  C(1, 2) = std::nan("");
  CHECK_THROWS_WITH_AS(linear_assignment(C), doctest::Contains("cost(1, 2) is NaN"), ArgumentError);
  C(1, 2) = -inf;
  CHECK_THROWS_WITH_AS(linear_assignment(C), doctest::Contains("-inf"), ArgumentError);
  C.setConstant(inf);
  C(0, 1) = 1;
  C(1, 1) = 2;  // both rows can only use column 1
  CHECK_THROWS_WITH_AS(linear_assignment(C), doctest::Contains("infeasible: row 1"), ArgumentError);
  C.row(0).setConstant(inf);
  CHECK_THROWS_WITH_AS(linear_assignment(C), doctest::Contains("row 0"), ArgumentError);
  CHECK(linear_assignment(Eigen::MatrixXd(0, 4)).row_to_col.size() == 0);
}

TEST_CASE("sparse_assignment: identical to the dense solver on complete and random sparse graphs") {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    const Index n = 5 + trial % 23, m = n + trial % 17;
    Eigen::MatrixXd C(n, m);
    std::uniform_int_distribution<int> small(0, 6);
    std::uniform_real_distribution<double> real(0, 1);
    for (Index i = 0; i < C.size(); ++i) C.data()[i] = trial % 2 ? small(rng) : real(rng);
    if (trial % 4 >= 2) {  // drop ~60% of the edges, keeping a random perfect matching
      std::vector<Index> p(static_cast<std::size_t>(m));
      std::iota(p.begin(), p.end(), 0);
      std::shuffle(p.begin(), p.end(), rng);
      for (Index i = 0; i < n; ++i)
        for (Index j = 0; j < m; ++j)
          if (j != p[i] && real(rng) < 0.6) C(i, j) = inf;
    }
    CAPTURE(trial);
    const auto d = linear_assignment(C);
    const SparseCostGraph g = full_graph(C);
    const auto s = sparse_assignment(g);
    REQUIRE(s.feasible);
    check_is_assignment(s.row_to_col, m);
    CHECK(s.total_cost == d.total_cost);  // identical bits: integers, or the unique real optimum
    if (trial % 2 == 0) CHECK(s.row_to_col == d.row_to_col);
    const auto cert = certify(g, s);
    CHECK(cert.optimal);
    CHECK(cert.max_dual_violation <= cert.tolerance);
    CHECK(std::abs(cert.duality_gap) <= cert.tolerance);
  }
}

TEST_CASE("sparse_assignment: reports a violated Hall set, validates input, certifies") {
  SparseCostGraph g(4, 5);
  for (const auto& row : std::vector<std::vector<int>>{{0, 1}, {1}, {0, 1}, {2, 3, 4}}) {
    for (const int j : row) g.add(j, 1.0 + j);
    g.end_row();
  }
  const auto s = sparse_assignment(g);
  CHECK_FALSE(s.feasible);
  CHECK(s.hall_rows == std::vector<VIndex>{0, 1, 2});  // three rows, two columns
  CHECK_THROWS_AS(certify(g, s), ArgumentError);

  SparseCostGraph bad(1, 2);
  bad.add(2, 1.0);
  bad.end_row();
  CHECK_THROWS_WITH_AS(sparse_assignment(bad), doctest::Contains("outside [0, 2)"), ArgumentError);
  SparseCostGraph nanc(1, 2);
  nanc.add(0, std::nan(""));
  nanc.end_row();
  CHECK_THROWS_WITH_AS(sparse_assignment(nanc), doctest::Contains("not finite"), ArgumentError);
  SparseCostGraph open(1, 2);
  open.add(0, 1.0);
  CHECK_THROWS_WITH_AS(sparse_assignment(open), doctest::Contains("end_row"), ArgumentError);

  // A deliberately wrong dual breaks the certificate: the check is not vacuous.
  SparseCostGraph h(2, 2);
  h.add(0, 1.0), h.add(1, 2.0), h.end_row();
  h.add(0, 1.0), h.add(1, 5.0), h.end_row();
  auto t = sparse_assignment(h);
  REQUIRE(t.feasible);
  CHECK(t.total_cost == 3.0);
  CHECK(certify(h, t).optimal);
  t.row_dual[0] += 0.5;
  CHECK_FALSE(certify(h, t).optimal);
}

TEST_CASE("assign_points: equals the dense optimum on clustered points with exact duplicates, seq == omp") {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 24; ++trial) {
    const Index n = 20 + 9 * trial, m = n + 1 + (trial * 37) % (2 * n);
    const bool dup = trial % 2 == 1;
    const Points<> A = clustered_points(n, 1 + trial % 4, rng, dup);
    const Points<> B = clustered_points(m, 1 + trial % 3, rng, dup);
    CAPTURE(trial);
    const auto C = distance_matrix(A, B);
    const auto d = linear_assignment(C);
    PointAssignmentOptions opt;
    opt.k = 1 + trial % 5;  // tiny k: Hall failures and certificate growth must both repair it
    const auto s = assign_points(exec::seq, A, B, opt);
    const auto o = assign_points(exec::omp, A, B, opt);
    check_is_assignment(s.row_to_col, m);
    CHECK(s.globally_optimal);
    CHECK(s.certificate.optimal);
    CHECK(s.total_cost == doctest::Approx(d.total_cost).epsilon(1e-13));
    if (!dup) CHECK(s.total_cost == d.total_cost);
    CHECK(o.row_to_col == s.row_to_col);
    CHECK(o.total_cost == s.total_cost);
    CHECK(o.log == s.log);
    CHECK(s.rounds == Index(s.log.size()));
    // The proof is global: check the duals on all N·M pairs.
    double worst = -inf;
    for (Index i = 0; i < n; ++i)
      for (Index j = 0; j < m; ++j) worst = std::max(worst, s.row_dual[i] + s.col_dual[j] - C(i, j));
    CHECK(worst <= 1e-9);
  }
}

TEST_CASE("assign_points: grows candidates when k nearest cannot be matched, and says so") {
  // Ten points stacked on one spot, targets on a line: every point's nearest target is the same.
  Points<> A = Points<>::Zero(10, 3);
  Points<> B(30, 3);
  for (Index j = 0; j < 30; ++j) B.row(j) << 0.1 * (j + 1), 0, 0;
  PointAssignmentOptions opt;
  opt.k = 1;
  const auto s = assign_points(exec::seq, A, B, opt);
  CHECK(s.rounds > 1);
  CHECK(s.log.front().find("no complete matching") != std::string::npos);
  CHECK(s.globally_optimal);
  CHECK(s.total_cost == doctest::Approx(0.1 * 55));  // the ten nearest targets
  opt.prove_global = false;
  opt.max_rounds = 1;
  CHECK_THROWS_AS(assign_points(exec::seq, A, B, opt), ConvergenceError);

  CHECK_THROWS_AS(assign_points(exec::seq, B, A), ShapeError);
  CHECK_THROWS_AS(assign_points(exec::seq, Eigen::MatrixXd::Zero(2, 2), B), ShapeError);
  Points<> bad = A;
  bad(3, 1) = std::nan("");
  CHECK_THROWS_WITH_AS(assign_points(exec::seq, bad, B), doctest::Contains("from row 3"), ArgumentError);
  opt.k = 0;
  CHECK_THROWS_AS(assign_points(exec::seq, A, B, opt), ArgumentError);
}
