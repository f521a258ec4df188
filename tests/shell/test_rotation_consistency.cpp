#include <doctest/doctest.h>

#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/shell/rotation_consistency.hpp>

#include <bit>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>

#include "../support/error_of.hpp"

namespace shell_test_rotation_consistency {

using namespace simsr;
using namespace simsr::shell;
constexpr double pi = std::numbers::pi;

namespace {

/// The exact optimum of Eq. 2 by enumerating every sign vector (o_0 = 1 when the gauge is fixed)
/// in Gray-code order: one flip per step, the objective updated by the flipped vertex's field.
std::int64_t best_signs(const AxisSignProblem& P) {
  const Index n = P.num_vertices();
  // the adjacency rebuilt from the edges here, independently of consistency_graph's edge_of
  const Edges& E = P.graph->edges;
  const Adjacency A = vertex_adjacency(E, n);
  std::vector<int> score(A.neighbors.size(), 0);
  for (Index e = 0; e < E.rows(); ++e)
    for (int side = 0; side < 2; ++side) {
      const Index a = E(e, side), b = E(e, 1 - side);
      for (Index k = A.offsets[a]; k < A.offsets[a + 1]; ++k)
        if (A.neighbors[k] == b) score[k] += P.edge_score[e];
    }
  std::vector<int> o(static_cast<std::size_t>(n), 1);
  std::int64_t J = P.objective(o), best = J;
  const Index first = P.fix_first ? 1 : 0, free = n - first;
  for (std::uint64_t step = 1; step < (std::uint64_t(1) << free); ++step) {
    const Index i = first + std::countr_zero(step);  // Gray code: flip bit ctz(step)
    std::int64_t h = P.vertex_score[i];
    for (Index k = A.offsets[i]; k < A.offsets[i + 1]; ++k) h += score[k] * o[A.neighbors[k]];
    J -= 2 * o[i] * h;
    o[i] = -o[i];
    best = std::max(best, J);
  }
  return best;
}

/// The exact optimum of Eq. 4 over r ∈ [−range, range]ⁿ (r_0 = 0 when the gauge is fixed), by
/// enumeration in odometer order, the objective updated by the terms at each changed vertex. The
/// instances below keep every angle within 5.5π (random) or 3.4π (smooth) of 0, so the optimum
/// lies inside range 3 (random) or 2 (smooth).
double best_cycles(const AngleCycleProblem& P, int range) {
  constexpr double two_pi = 2 * pi;
  const Index n = P.num_vertices();
  const Adjacency A = vertex_adjacency(P.graph->edges, n);
  std::vector<int> r(static_cast<std::size_t>(n), -range);
  if (P.fix_first) r[0] = 0;
  auto local = [&](Index i) {  // the terms at vertex i (edges counted from i's side only)
    double F = 0;
    for (const VIndex j : A[i]) {
      const double d = two_pi * (r[i] - r[j]) + P.phi[i] - P.phi[j];
      F += d * d;
    }
    if (P.previous) {
      const double d = two_pi * r[i] + P.phi[i] - (*P.previous)[i];
      F += d * d;
    }
    return F;
  };
  // changing r_i moves its edge terms (each shared with a neighbour: counted once in local(i)
  // and once in local(j), so the change of the sum of edge terms is the change of local(i)'s
  // edge part) and its own temporal term
  auto set = [&](Index i, int value, double& F) {
    const double before = local(i);
    r[i] = value;
    F += local(i) - before;
  };
  double F = P.objective(r), best = F;
  std::vector<int> argmin = r;
  for (;;) {
    Index i = P.fix_first ? 1 : 0;
    while (i < n && r[i] == range) set(i, -range, F), ++i;
    if (i == n) break;
    set(i, r[i] + 1, F);
    if (F < best) best = F, argmin = r;
  }
  return P.objective(argmin);  // exactly, without the updates' rounding
}

/// Axes and angles of a smooth rotation field (a twist along x plus a bend) with noise `noise`,
/// reduced to principal form, as the encoder sees them.
void field(const Points<>& X, double amount, double noise, std::mt19937& rng, std::vector<Vec3<>>& axis,
           std::vector<double>& theta) {
  std::normal_distribution<double> g;
  axis.resize(X.rows());
  theta.resize(X.rows());
  for (Index i = 0; i < X.rows(); ++i) {
    Vec3<> rho = amount * Vec3<>(1.0 + 0.5 * X(i, 0), 0.4 * X(i, 1), 0.2) + noise * Vec3<>(g(rng), g(rng), g(rng));
    const Eigen::AngleAxisd aa{Eigen::Quaterniond(Eigen::AngleAxisd(rho.norm(), rho.normalized()))};
    axis[i] = aa.axis();
    theta[i] = aa.angle();
  }
}

AxisSignProblem sign_problem(const ConsistencyGraph& G, const std::vector<Vec3<>>& axis, const std::vector<double>& theta,
                             const std::vector<Vec3<>>* prev_axis, const std::vector<double>* prev_theta) {
  AxisSignProblem P;
  const ConsistencyThresholds th;
  P.graph = &G;
  const Edges& E = G.edges;
  P.fix_first = prev_axis == nullptr;
  for (Index e = 0; e < E.rows(); ++e)
    P.edge_score.push_back(orientation_score(axis[E(e, 0)].dot(axis[E(e, 1)]), theta[E(e, 0)], theta[E(e, 1)], th));
  for (std::size_t i = 0; i < axis.size(); ++i)
    P.vertex_score.push_back(prev_axis ? orientation_score(axis[i].dot((*prev_axis)[i]), theta[i], (*prev_theta)[i], th) : 0);
  return P;
}

}  // namespace

TEST_CASE("orientation_score: Eq. 3's three cases") {
  const ConsistencyThresholds th{0.1, 1e-3};
  CHECK(orientation_score(0.5, 1.0, 1.0, th) == 1);
  CHECK(orientation_score(-0.5, 1.0, 1.0, th) == -1);
  CHECK(orientation_score(0.05, 1.0, 1.0, th) == 0);   // axes too far apart to say
  CHECK(orientation_score(0.9, 1e-4, 1.0, th) == 0);   // an angle too small for its axis to mean anything
  CHECK(orientation_score(-0.9, 1.0, 1e-4, th) == 0);
}

TEST_CASE("solve_axis_signs: how often propagation + local improvement reaches Eq. 2's optimum (enumerated)") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  struct Tally { int optimal = 0, total = 0; };
  Tally smooth, random;
  for (const Index rings : {1, 2}) {
    const TriMesh<> disk = disk_surface(1.0, rings);
    const ConsistencyGraph G = consistency_graph(unique_edges(disk.F), disk.V.rows());
    for (int k = 0; k < (rings == 1 ? 300 : 40); ++k) {
      std::vector<Vec3<>> axis, prev_axis;
      std::vector<double> theta, prev_theta;
      const bool temporal = k % 2 == 1, is_random = k % 4 >= 2;
      field(disk.V, 0.5 + 2.5 * (u(rng) + 1), is_random ? 2.0 : 0.15, rng, axis, theta);
      field(disk.V, 0.5 + 2.5 * (u(rng) + 1), is_random ? 2.0 : 0.15, rng, prev_axis, prev_theta);
      const AxisSignProblem P = sign_problem(G, axis, theta, temporal ? &prev_axis : nullptr, &prev_theta);
      ConsistencySolveStats stats;
      const std::vector<int> o = solve_axis_signs(P, &stats);
      if (P.fix_first) CHECK(o[0] == 1);
      Tally& t = is_random ? random : smooth;
      ++t.total;
      const std::int64_t got = P.objective(o), best = best_signs(P);
      CHECK(got <= best);
      t.optimal += got == best;
    }
  }
  MESSAGE("Eq. 2 optimum reached: smooth fields " << smooth.optimal << "/" << smooth.total << ", random axes "
                                                  << random.optimal << "/" << random.total);
  CHECK(smooth.optimal == smooth.total);  // the case the encoder meets: a field that varies smoothly
  CHECK(random.optimal >= 0.8 * random.total);  // frustrated instances: a heuristic, measured
}

TEST_CASE("solve_angle_cycles: how often propagation + local improvement reaches Eq. 4's optimum (enumerated)") {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(-1, 1);
  const TriMesh<> disk = disk_surface(1.0, 1);
  const ConsistencyGraph G = consistency_graph(unique_edges(disk.F), disk.V.rows());
  int smooth_opt = 0, smooth_total = 0, random_opt = 0, random_total = 0;
  for (int k = 0; k < 200; ++k) {
    const bool temporal = k % 2 == 1, is_random = k % 4 >= 2;
    AngleCycleProblem P;
    P.graph = &G;
    P.fix_first = !temporal;
    const double center = 3 * u(rng);
    for (Index i = 0; i < disk.V.rows(); ++i) {
      const double true_angle = center + (is_random ? 2.5 : 0.4) * u(rng);  // within ±3π·(<1)
      P.phi.push_back(std::remainder(true_angle * pi, 2 * pi));                // what the solver sees
    }
    if (temporal) {
      std::vector<double> prev;
      for (Index i = 0; i < disk.V.rows(); ++i) prev.push_back(center * pi + (is_random ? 3.0 : 0.3) * u(rng));
      P.previous = prev;
    }
    const std::vector<int> r = solve_angle_cycles(P);
    if (P.fix_first) CHECK(r[0] == 0);
    const double got = P.objective(r), best = best_cycles(P, is_random ? 3 : 2);  // smooth: every |angle| < 3.4π
    CHECK(got >= best - 1e-9);
    const bool opt = got <= best + 1e-9 * (1 + best);
    (is_random ? random_opt : smooth_opt) += opt;
    ++(is_random ? random_total : smooth_total);
  }
  MESSAGE("Eq. 4 optimum reached: smooth " << smooth_opt << "/" << smooth_total << ", random " << random_opt << "/"
                                           << random_total);
  CHECK(smooth_opt == smooth_total);
  CHECK(random_opt >= 0.8 * random_total);
}

TEST_CASE("solve_angle_cycles: a field that winds past π unwraps to the continuous angles") {
  // a strip whose true angle grows 0 → 5π along it: the principal values jump, the solution does not
  const TriMesh<> sheet = square_sheet(1.0, 12);
  const ConsistencyGraph G = consistency_graph(unique_edges(sheet.F), sheet.V.rows());
  AngleCycleProblem P;
  P.graph = &G;
  std::vector<double> truth;
  for (Index i = 0; i < sheet.V.rows(); ++i) {
    truth.push_back(5 * pi * sheet.V(i, 0) + 0.3 * sheet.V(i, 1));
    P.phi.push_back(std::remainder(truth.back(), 2 * pi));
  }
  const std::vector<int> r = solve_angle_cycles(P);
  for (Index i = 0; i < sheet.V.rows(); ++i) CHECK(2 * pi * r[i] + P.phi[i] == doctest::Approx(truth[i]).epsilon(1e-12));
}

TEST_CASE("rotation consistency: malformed problems are typed errors") {
  Edges bad(1, 2);
  bad << 0, 5;
  CHECK(!test::typed_error_of<MeshError>([&] { consistency_graph(bad, 2); }).empty());  // vertex 5 of 2
  Edges one(1, 2);
  one << 0, 1;
  const ConsistencyGraph G = consistency_graph(one, 2);
  AxisSignProblem P;
  P.edge_score = {1};
  P.vertex_score = {0, 0};
  CHECK(!test::typed_error_of<ArgumentError>([&] { solve_axis_signs(P); }).empty());  // no graph
  P.graph = &G;
  P.vertex_score = {0, 0, 0};
  CHECK(!test::typed_error_of<ShapeError>([&] { solve_axis_signs(P); }).empty());  // 3 values, 2 vertices
  P.vertex_score = {0, 0};
  P.edge_score = {};
  CHECK(!test::typed_error_of<ShapeError>([&] { solve_axis_signs(P); }).empty());
  AngleCycleProblem Q;
  Q.graph = &G;
  Q.phi = {0.0, 1.0};
  Q.previous = std::vector<double>{0.0};
  CHECK(!test::typed_error_of<ShapeError>([&] { solve_angle_cycles(Q); }).empty());
}

}  // namespace shell_test_rotation_consistency
