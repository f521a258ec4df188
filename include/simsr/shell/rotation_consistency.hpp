#pragma once
/// \file
/// The two integer problems that make TS-ACAP's rotations consistent over space and time
/// (Chen et al. 2023 supplement Eq. 2–4; Gao et al. 2019). A rotation R_i has infinitely many
/// axis–angle forms: (ω, θ + 2πk) and (−ω, −θ + 2πk). Per frame t, with frame t−1 already fixed:
///
///  Eq. 2  axis signs o_i ∈ {±1} maximizing  Σ_{ij∈E} o_i o_j s(ω_i·ω_j) + Σ_i o_i s(ω_i·ω̂ᵗ⁻¹_i)
///  Eq. 4  cycles r_i ∈ ℤ minimizing  Σ_{ij∈E} (2π(r_i − r_j) + φ_i − φ_j)² + Σ_i (2πr_i + φ_i − Φᵗ⁻¹_i)²
///
/// with s of Eq. 3 (±1 when the axes agree/disagree beyond ε₁, 0 when either angle is below ε₂),
/// φ_i = o_i θ_i, ω̂ = o ω the oriented axis and Φ = 2πr + φ the unwrapped angle. The paper solves
/// both with CoMISo's mixed-integer solver; this file solves them with
///
///  1. propagation: a breadth-first sweep from vertex 0 that gives each vertex the label best for
///     its already-labelled neighbours (and its previous frame), then
///  2. local improvement to a fixed point: single-vertex moves (a flip; the exact integer
///     minimiser in r_i given its neighbours) and cluster moves (flipping, or shifting by ±1,
///     a connected set of vertices whose shared edges are all consistent), each accepted only
///     when it strictly improves the objective, so the loop ends.
///
/// tests/shell/test_rotation_consistency.cpp measures how often this reaches the exact optimum
/// on problems small enough to enumerate. Gauge: Eq. 2 and 4 fix vertex 0 (o = 1, r = 0). That
/// is kept where nothing else fixes the gauge (the first frame of a sequence); in later frames
/// the temporal terms do, and fixing vertex 0 would break its own continuity when it rotates
/// through π, so it is free there.

#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <queue>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../mesh/topology.hpp"

namespace simsr::shell {

/// ε₁ and ε₂ of Eq. 3 (the paper leaves them open).
struct ConsistencyThresholds {
  double axis_dot = 0.1;    ///< ε₁: |ω_i·ω_j| ≤ ε₁ says nothing about agreement (axes ~84°+ apart)
  double min_angle = 1e-3;  ///< ε₂: below this angle (rad) the axis is noise and scores 0
};

/// s of Eq. 3 for two axes with angles θa, θb.
inline int orientation_score(double dot, double theta_a, double theta_b, const ConsistencyThresholds& th) {
  if (std::abs(dot) <= th.axis_dot || theta_a < th.min_angle || theta_b < th.min_angle) return 0;
  return dot > 0 ? 1 : -1;
}

/// The graph both problems live on, built once per mesh (not per frame): its edges, the vertex
/// adjacency, and for each adjacency entry the edge it stands for.
struct ConsistencyGraph {
  Edges edges;
  Adjacency adjacency;
  std::vector<Index> edge_of;  ///< edge index of adjacency.neighbors[k]

  Index num_vertices() const { return adjacency.num_vertices(); }
};

/// The graph of `edges` (#E×2, unique) over n vertices. MeshError for an index outside [0, n).
inline ConsistencyGraph consistency_graph(Edges edges, Index n) {
  ConsistencyGraph G;
  G.adjacency = vertex_adjacency(edges, n);
  G.edge_of.assign(G.adjacency.neighbors.size(), -1);
  for (Index e = 0; e < edges.rows(); ++e)
    for (int side = 0; side < 2; ++side) {
      const Index a = edges(e, side), b = edges(e, 1 - side);
      for (Index k = G.adjacency.offsets[a]; k < G.adjacency.offsets[a + 1]; ++k)
        if (G.adjacency.neighbors[k] == b) G.edge_of[k] = e;
    }
  G.edges = std::move(edges);
  return G;
}

/// Eq. 2 for one frame, scores precomputed: edge_score[e] = s for edges(e, ·), vertex_score[i] =
/// the temporal s of vertex i (all 0 in a first frame).
struct AxisSignProblem {
  const ConsistencyGraph* graph = nullptr;
  std::vector<int> edge_score;
  std::vector<int> vertex_score;
  bool fix_first = true;  ///< o_0 = 1 (the gauge of a first frame)

  Index num_vertices() const { return static_cast<Index>(vertex_score.size()); }
  /// The objective of Eq. 2 (to maximize).
  std::int64_t objective(const std::vector<int>& o) const {
    std::int64_t J = 0;
    const Edges& E = graph->edges;
    for (Index e = 0; e < E.rows(); ++e) J += std::int64_t(o[E(e, 0)]) * o[E(e, 1)] * edge_score[e];
    for (std::size_t i = 0; i < vertex_score.size(); ++i) J += std::int64_t(o[i]) * vertex_score[i];
    return J;
  }
};

/// Eq. 4 for one frame: phi[i] = o_i θ_i; previous[i] = Φᵗ⁻¹_i when there is a previous frame.
struct AngleCycleProblem {
  const ConsistencyGraph* graph = nullptr;
  std::vector<double> phi;
  std::optional<std::vector<double>> previous;
  bool fix_first = true;  ///< r_0 = 0 (the gauge of a first frame)

  Index num_vertices() const { return static_cast<Index>(phi.size()); }
  /// The objective of Eq. 4 (to minimize).
  double objective(const std::vector<int>& r) const {
    constexpr double two_pi = 2 * std::numbers::pi;
    double F = 0;
    const Edges& E = graph->edges;
    for (Index e = 0; e < E.rows(); ++e) {
      const Index i = E(e, 0), j = E(e, 1);
      const double d = two_pi * (r[i] - r[j]) + phi[i] - phi[j];
      F += d * d;
    }
    if (previous)
      for (std::size_t i = 0; i < phi.size(); ++i) {
        const double d = two_pi * r[i] + phi[i] - (*previous)[i];
        F += d * d;
      }
    return F;
  }
};

/// What the local improvement did (for reports and tests).
struct ConsistencySolveStats {
  Index single_moves = 0;
  Index cluster_moves = 0;
  Index passes = 0;
};

namespace detail {

/// Breadth-first order of every vertex (component by component, each from its lowest index) and
/// each vertex's BFS parent (−1 for a component's root).
inline void bfs_order(const Adjacency& A, std::vector<Index>& order, std::vector<Index>& parent) {
  const Index n = A.num_vertices();
  order.clear();
  parent.assign(static_cast<std::size_t>(n), -2);
  for (Index root = 0; root < n; ++root) {
    if (parent[root] != -2) continue;
    parent[root] = -1;
    std::size_t head = order.size();
    order.push_back(root);
    while (head < order.size()) {
      const Index v = order[head++];
      for (const VIndex w : A[v])
        if (parent[w] == -2) parent[w] = v, order.push_back(w);
    }
  }
}

/// Components of the graph restricted to the edges `keep(e)` accepts; label per vertex.
template <class Keep>
std::vector<Index> edge_components(const Edges& E, Index n, Keep&& keep, Index& count) {
  std::vector<Index> up(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) up[i] = i;
  auto find = [&](Index x) {
    while (up[x] != x) x = up[x] = up[up[x]];
    return x;
  };
  for (Index e = 0; e < E.rows(); ++e)
    if (keep(e)) {
      const Index a = find(E(e, 0)), b = find(E(e, 1));
      if (a != b) up[std::max(a, b)] = std::min(a, b);
    }
  std::vector<Index> label(static_cast<std::size_t>(n), -1), id(static_cast<std::size_t>(n), -1);
  count = 0;
  for (Index i = 0; i < n; ++i) {
    const Index r = find(i);
    if (id[r] < 0) id[r] = count++;
    label[i] = id[r];
  }
  return label;
}

/// ArgumentError without a graph, ShapeError when the problem's vertex count is not the graph's.
inline void check_problem_graph(const char* what, const ConsistencyGraph* G, Index n) {
  if (!G) throw ArgumentError(std::string(what) + ": the problem has no graph (consistency_graph)");
  if (G->num_vertices() != n) throw ShapeError(std::string(what) + ": per-vertex values", {G->num_vertices()}, {n});
}

}  // namespace detail

/// Solves Eq. 2 by propagation and local improvement (see the file comment). Returns o (±1 each).
inline std::vector<int> solve_axis_signs(const AxisSignProblem& P, ConsistencySolveStats* stats = nullptr) {
  const Index n = P.num_vertices();
  detail::check_problem_graph("solve_axis_signs", P.graph, n);
  const Edges& E = P.graph->edges;
  const Adjacency& A = P.graph->adjacency;
  if (static_cast<Index>(P.edge_score.size()) != E.rows())
    throw ShapeError("solve_axis_signs: edge_score", {E.rows()}, {static_cast<std::int64_t>(P.edge_score.size())});
  std::vector<int> score(A.neighbors.size());  // the score of each adjacency entry
  for (std::size_t k = 0; k < score.size(); ++k) score[k] = P.edge_score[std::size_t(P.graph->edge_of[k])];
  std::vector<int> o(static_cast<std::size_t>(n), 0);
  auto field = [&](Index i) {  // h_i = vertex term + Σ_j s_ij o_j (unlabelled neighbours count 0)
    int h = P.vertex_score[i];
    for (Index k = A.offsets[i]; k < A.offsets[i + 1]; ++k) h += score[k] * o[A.neighbors[k]];
    return h;
  };
  std::vector<Index> order, parent;
  detail::bfs_order(A, order, parent);
  for (const Index v : order) o[v] = (P.fix_first && v == 0) ? 1 : (field(v) >= 0 ? 1 : -1);
  ConsistencySolveStats s;
  for (bool changed = true; changed;) {
    changed = false;
    ++s.passes;
    for (Index i = 0; i < n; ++i) {
      if (P.fix_first && i == 0) continue;
      if (o[i] * field(i) < 0) o[i] = -o[i], ++s.single_moves, changed = true;
    }
    // cluster flips: components joined by satisfied non-zero edges; flipping one changes only
    // its boundary edges and its members' temporal terms
    Index count = 0;
    const std::vector<Index> label = detail::edge_components(
        E, n, [&](Index e) { return P.edge_score[e] * o[E(e, 0)] * o[E(e, 1)] > 0; }, count);
    std::vector<std::int64_t> gain(static_cast<std::size_t>(count), 0);  // objective change of a flip
    std::vector<char> pinned(static_cast<std::size_t>(count), 0);
    for (Index i = 0; i < n; ++i) gain[label[i]] -= 2 * std::int64_t(o[i]) * P.vertex_score[i];
    if (P.fix_first && n > 0) pinned[label[0]] = 1;
    for (Index e = 0; e < E.rows(); ++e) {
      const Index a = E(e, 0), b = E(e, 1);
      if (label[a] == label[b]) continue;
      const std::int64_t term = std::int64_t(o[a]) * o[b] * P.edge_score[e];
      gain[label[a]] -= 2 * term;
      gain[label[b]] -= 2 * term;
    }
    // flip the best improving cluster only (two flips' gains are not additive when adjacent)
    Index best = -1;
    for (Index c = 0; c < count; ++c)
      if (!pinned[c] && gain[c] > 0 && (best < 0 || gain[c] > gain[best])) best = c;
    if (best >= 0) {
      for (Index i = 0; i < n; ++i)
        if (label[i] == best) o[i] = -o[i];
      ++s.cluster_moves;
      changed = true;
    }
  }
  if (stats) *stats = s;
  return o;
}

/// Solves Eq. 4 by propagation and local improvement (see the file comment). Returns r.
inline std::vector<int> solve_angle_cycles(const AngleCycleProblem& P, ConsistencySolveStats* stats = nullptr) {
  constexpr double two_pi = 2 * std::numbers::pi;
  const Index n = P.num_vertices();
  detail::check_problem_graph("solve_angle_cycles", P.graph, n);
  const Edges& E = P.graph->edges;
  if (P.previous && static_cast<Index>(P.previous->size()) != n)
    throw ShapeError("solve_angle_cycles: previous angles", {n}, {static_cast<std::int64_t>(P.previous->size())});
  const Adjacency& A = P.graph->adjacency;
  std::vector<int> r(static_cast<std::size_t>(n), 0);
  const bool has_prev = P.previous.has_value();
  if (has_prev) {
    for (Index i = 0; i < n; ++i) r[i] = static_cast<int>(std::lround(((*P.previous)[i] - P.phi[i]) / two_pi));
  } else {
    std::vector<Index> order, parent;
    detail::bfs_order(A, order, parent);
    for (const Index v : order)
      r[v] = parent[v] < 0 ? 0 : static_cast<int>(std::lround(r[parent[v]] + (P.phi[parent[v]] - P.phi[v]) / two_pi));
  }
  if (P.fix_first && n > 0 && r[0] != 0) {  // the gauge: shift every component-0 label so r_0 = 0
    const int shift = r[0];
    Index count = 0;
    const std::vector<Index> label = detail::edge_components(E, n, [](Index) { return true; }, count);
    for (Index i = 0; i < n; ++i)
      if (label[i] == label[0]) r[i] -= shift;
  }
  // F restricted to r_i: Σ_j (2π(r_i − r_j) + φ_i − φ_j)² + [prev](2πr_i + φ_i − Φ_i)²
  auto local = [&](Index i, int ri) {
    double F = 0;
    for (const VIndex j : A[i]) {
      const double d = two_pi * (ri - r[j]) + P.phi[i] - P.phi[j];
      F += d * d;
    }
    if (has_prev) {
      const double d = two_pi * ri + P.phi[i] - (*P.previous)[i];
      F += d * d;
    }
    return F;
  };
  ConsistencySolveStats s;
  for (bool changed = true; changed;) {
    changed = false;
    ++s.passes;
    if (s.passes > 100 * (n + 1)) throw ConvergenceError("solve_angle_cycles", s.passes, 0.0);
    for (Index i = 0; i < n; ++i) {
      if (P.fix_first && i == 0) continue;
      const double count = double(A.degree(i)) + (has_prev ? 1 : 0);
      if (count == 0) continue;
      double sum = 0;
      for (const VIndex j : A[i]) sum += two_pi * r[j] + P.phi[j] - P.phi[i];
      if (has_prev) sum += (*P.previous)[i] - P.phi[i];
      const int best = static_cast<int>(std::lround(sum / (two_pi * count)));
      if (best != r[i] && local(i, best) < local(i, r[i]) - 1e-12) r[i] = best, ++s.single_moves, changed = true;
    }
    // cluster shifts: components joined by edges already within (−π, π]; shifting one by ±1
    // changes its boundary edges and its members' temporal terms only
    Index count = 0;
    const std::vector<Index> label = detail::edge_components(
        E, n,
        [&](Index e) {
          const Index a = E(e, 0), b = E(e, 1);
          return std::abs(two_pi * (r[a] - r[b]) + P.phi[a] - P.phi[b]) < std::numbers::pi;
        },
        count);
    std::vector<double> up(static_cast<std::size_t>(count), 0), down(static_cast<std::size_t>(count), 0);
    std::vector<char> pinned(static_cast<std::size_t>(count), 0);
    if (P.fix_first && n > 0) pinned[label[0]] = 1;
    auto add = [&](Index c, double d) {  // change of d² when d moves by ±2π
      up[c] += (d + two_pi) * (d + two_pi) - d * d;
      down[c] += (d - two_pi) * (d - two_pi) - d * d;
    };
    if (has_prev)
      for (Index i = 0; i < n; ++i) add(label[i], two_pi * r[i] + P.phi[i] - (*P.previous)[i]);
    for (Index e = 0; e < E.rows(); ++e) {
      const Index a = E(e, 0), b = E(e, 1);
      if (label[a] == label[b]) continue;
      const double d = two_pi * (r[a] - r[b]) + P.phi[a] - P.phi[b];
      add(label[a], d);
      add(label[b], -d);
    }
    Index best = -1;
    int step = 0;
    double best_change = -1e-9;
    for (Index c = 0; c < count; ++c) {
      if (pinned[c]) continue;
      if (up[c] < best_change) best_change = up[c], best = c, step = 1;
      if (down[c] < best_change) best_change = down[c], best = c, step = -1;
    }
    if (best >= 0) {
      for (Index i = 0; i < n; ++i)
        if (label[i] == best) r[i] += step;
      ++s.cluster_moves;
      changed = true;
    }
  }
  if (stats) *stats = s;
  return r;
}

}  // namespace simsr::shell
