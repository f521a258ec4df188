#pragma once
/// \file
/// A scalar field on a mesh's vertex graph that takes given values on some vertices and is
/// harmonic everywhere else (each free vertex the mean of its neighbours: the minimizer of
/// Σ_edges (w_i − w_j)², the uniform graph Laplacian with Dirichlet conditions). The smooth skinning
/// weights of a bone (Baran & Popović 2007 use the same equation with a heat term).

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "topology.hpp"

namespace simsr {

/// The harmonic field on graph `A` with w[fixed[k]] = values[k]. A vertex that no path joins to a
/// fixed vertex takes `unreachable` (its block has no boundary value; the field there is
/// arbitrary otherwise). Solved by Jacobi-preconditioned conjugate gradients to `tolerance`
/// (relative residual); ConvergenceError when it is not reached. Throws MeshError for a fixed
/// vertex out of range or given twice, ArgumentError for non-finite values, ShapeError for sizes.
template <exec::HostPolicy P>
VecX<> harmonic_field(P policy, const Adjacency& A, const IndexVector& fixed, const VecX<>& values, double unreachable = 0,
                      double tolerance = 1e-10) {
  const Index n = A.num_vertices();
  if (values.size() != fixed.size()) throw ShapeError("harmonic_field: values", {fixed.size(), 1}, {values.size(), 1});
  if (!values.allFinite()) throw ArgumentError("harmonic_field: non-finite boundary values");
  if (!std::isfinite(unreachable)) throw ArgumentError("harmonic_field: non-finite value for unreachable vertices");
  // -1 free, otherwise the index into `values`
  std::vector<Index> given(std::size_t(n), -1);
  for (Index k = 0; k < fixed.size(); ++k) {
    const Index v = fixed[k];
    if (v < 0 || v >= n) throw MeshError("vertex", v, "harmonic_field: fixed vertex out of range [0, " + std::to_string(n) + ")");
    if (given[std::size_t(v)] >= 0) throw MeshError("vertex", v, "harmonic_field: fixed twice");
    given[std::size_t(v)] = k;
  }
  VecX<> w = VecX<>::Constant(n, unreachable);
  for (Index k = 0; k < fixed.size(); ++k) w[fixed[k]] = values[k];

  // the free vertices a path joins to a fixed one (breadth first from every fixed vertex)
  std::vector<char> reached(std::size_t(n), 0);
  std::vector<Index> queue(fixed.data(), fixed.data() + fixed.size());
  for (const Index v : queue) reached[std::size_t(v)] = 1;
  for (std::size_t q = 0; q < queue.size(); ++q)
    for (const VIndex u : A[queue[q]])
      if (!reached[std::size_t(u)]) {
        reached[std::size_t(u)] = 1;
        queue.push_back(u);
      }
  std::vector<Index> unknown(std::size_t(n), -1), free;
  for (Index v = 0; v < n; ++v)
    if (given[std::size_t(v)] < 0 && reached[std::size_t(v)]) {
      unknown[std::size_t(v)] = Index(free.size());
      free.push_back(v);
    }
  if (free.empty()) return w;

  // (D − A_ff) w_f = A_fb w_b over the free vertices: symmetric positive definite, since every
  // block of free vertices touches a fixed one
  const Index m = Index(free.size());
  std::vector<Eigen::Triplet<double, Index>> entries;
  VecX<> rhs = VecX<>::Zero(m);
  for (Index r = 0; r < m; ++r) {
    const Index v = free[std::size_t(r)];
    entries.emplace_back(r, r, double(A.degree(v)));
    for (const VIndex u : A[v]) {
      if (unknown[std::size_t(u)] >= 0)
        entries.emplace_back(r, unknown[std::size_t(u)], -1.0);
      else
        rhs[r] += w[u];  // a fixed neighbour (a reached vertex's neighbours are all reached)
    }
  }
  Eigen::SparseMatrix<double, Eigen::ColMajor, Index> L(m, m);
  L.setFromTriplets(entries.begin(), entries.end());
  Eigen::ConjugateGradient<decltype(L), Eigen::Lower | Eigen::Upper> cg;
  cg.setTolerance(tolerance);
  cg.setMaxIterations(std::max<Index>(1000, 10 * m));
  cg.compute(L);
  const VecX<> wf = cg.solve(rhs);
  if (cg.info() != Eigen::Success || !wf.allFinite())
    throw ConvergenceError("harmonic_field: conjugate gradients", Index(cg.iterations()), cg.error());
  exec::parallel_for(policy, m, [&](Index r) { w[free[std::size_t(r)]] = wf[r]; });
  return w;
}

}  // namespace simsr
