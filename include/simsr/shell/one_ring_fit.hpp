#pragma once
/// \file
/// Per-vertex deformation gradients of a triangle mesh by weighted least squares over the one-ring
/// (Chen et al. 2023 supplement, Eq. 1; Gao et al. 2019's ACAP):
///
///     T_i = argmin_T  Σ_{j∈N(i)} w_ij ‖(p_i − p_j) − T (q_i − q_j)‖² + ‖σ_i n_i − T σ⁰_i n⁰_i‖²
///
/// q the rest positions, p the deformed ones. The second term is not in Eq. 1: it is the vertex
/// normal as one more "edge" (scaled by σ = normal_scale × the mean one-ring edge length of the
/// configuration), as the authors' ACAP code does (FeatureVector.cpp). Without it a flat rest
/// one-ring (every vertex of a flat sheet) leaves T's action on the normal undetermined, T is
/// singular and its rotation undefined.
///
/// Usage:
///
///     OneRingFit<double> fit(exec::omp, rest_V, F);          // rest geometry, once per mesh
///     std::vector<Mat3<double>> T = fit.gradients(exec::omp, V);  // per frame

#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <cmath>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../mesh/cotangent_laplacian.hpp"
#include "../mesh/detail/elements.hpp"
#include "../mesh/normals.hpp"
#include "../mesh/topology.hpp"

namespace simsr::shell {

/// The edge weights w_ij of Eq. 1 (the rest mesh's; the same in the fit and in the inverse solve).
enum class OneRingWeights {
  /// ACAP's: the cotangent weight c = ½(cot α + cot β) mapped to a positive number smoothly,
  /// e^c for c ≤ 0 and 1 + c above (the authors' `sexp`): obtuse pairs (c < 0) would otherwise
  /// make the least squares indefinite. The default.
  acap,
  /// Eq. 1 as printed: w = ½(cot α + cot β) itself. A rest edge with w < 0 is a MeshError; w = 0
  /// (a right-angled pair, as in a regular grid's diagonals) drops the edge from the fit.
  cotangent,
  /// w = 1 for every edge: an ablation.
  uniform,
};

struct OneRingFitOptions {
  OneRingWeights weights = OneRingWeights::acap;
  /// σ/mean edge length of the normal "edge" (the authors' RefMesh::normalScale).
  double normal_scale = 0.3;
};

/// Rest data of Eq. 1 for every vertex of a triangle mesh, and the per-frame fit.
template <class S = Scalar>
class OneRingFit {
 public:
  /// rest #V×3, F #F×3 (every vertex in some triangle). Throws MeshError for an unreferenced
  /// vertex or a one-ring whose fit is singular (all its rest edges collinear and no normal),
  /// ArgumentError for normal_scale ≤ 0 or non-finite rest positions.
  template <exec::HostPolicy P>
  OneRingFit(P policy, const Points<S>& rest, const Tris& F, OneRingFitOptions options = {})
      : options_(options), F_(F), rest_(rest) {
    if (!(options.normal_scale > 0)) throw ArgumentError("OneRingFit: normal_scale must be > 0");
    if (!rest.allFinite()) throw ArgumentError("OneRingFit: rest positions contain NaN or Inf");
    adjacency_ = vertex_adjacency(F, rest.rows());
    const Eigen::SparseMatrix<S> L = cotangent_laplacian(policy, rest, F);
    const Index n = rest.rows();
    weights_.resize(adjacency_.neighbors.size());
    for (Index i = 0; i < n; ++i) {
      if (adjacency_.degree(i) == 0) throw MeshError("vertex", i, "is in no triangle (OneRingFit)");
      for (Index k = adjacency_.offsets[i]; k < adjacency_.offsets[i + 1]; ++k)
        weights_[k] = edge_weight(L.coeff(i, adjacency_.neighbors[k]), i, adjacency_.neighbors[k]);
    }
    const Points<S> N = vertex_normals(rest, F);
    rest_normal_scaled_.resize(n, 3);
    rest_inverse_.resize(static_cast<std::size_t>(n));
    std::vector<std::string> problems(static_cast<std::size_t>(n));
    exec::parallel_for(policy, n, [&](Index i) {
      const Vec3<S> q = simsr::detail::point(rest, i);
      Mat3<S> M = Mat3<S>::Zero();
      S length = 0;
      for (Index k = adjacency_.offsets[i]; k < adjacency_.offsets[i + 1]; ++k) {
        const Vec3<S> e = q - simsr::detail::point(rest, adjacency_.neighbors[k]);
        M += weights_[k] * e * e.transpose();
        length += e.norm();
      }
      const Vec3<S> nrm = S(options_.normal_scale) * length / S(adjacency_.degree(i)) * simsr::detail::point(N, i);
      rest_normal_scaled_.row(i) = nrm.transpose();
      M += nrm * nrm.transpose();
      // Well-posed when M is far from singular relative to its own scale.
      const Eigen::FullPivLU<Mat3<S>> lu(M);
      if (lu.rank() < 3 || !(std::abs(M.determinant()) > S(1e-12) * std::pow(M.norm(), 3)))
        problems[static_cast<std::size_t>(i)] = "its one-ring fit (Eq. 1) is singular: rest edges collinear or degenerate";
      else
        rest_inverse_[static_cast<std::size_t>(i)] = lu.inverse();
    });
    for (Index i = 0; i < n; ++i)
      if (!problems[static_cast<std::size_t>(i)].empty()) throw MeshError("vertex", i, problems[static_cast<std::size_t>(i)]);
  }

  Index num_vertices() const { return rest_.rows(); }
  const Adjacency& adjacency() const { return adjacency_; }
  const Tris& faces() const { return F_; }
  const Points<S>& rest() const { return rest_; }
  /// w_ij for the adjacency's k-th entry (adjacency().neighbors[k]); symmetric in i, j.
  const std::vector<S>& weights() const { return weights_; }
  const OneRingFitOptions& options() const { return options_; }

  /// T_i of every vertex of V (#V×3, the rest mesh's connectivity). Throws ShapeError for a
  /// vertex count other than the rest mesh's, ArgumentError for NaN/Inf positions.
  template <exec::HostPolicy P>
  std::vector<Mat3<S>> gradients(P policy, const Points<S>& V) const {
    std::vector<Mat3<S>> T;
    gradients_into(policy, V, T);
    return T;
  }

  /// gradients() into a caller-owned buffer (resized once, then reused).
  template <exec::HostPolicy P>
  void gradients_into(P policy, const Points<S>& V, std::vector<Mat3<S>>& T) const {
    if (V.rows() != rest_.rows()) throw ShapeError("OneRingFit: positions", {rest_.rows(), 3}, {V.rows(), V.cols()});
    if (!V.allFinite()) throw ArgumentError("OneRingFit: positions contain NaN or Inf");
    const Points<S> N = vertex_normals(V, F_);
    T.resize(static_cast<std::size_t>(V.rows()));
    exec::parallel_for(policy, V.rows(), [&](Index i) {
      const Vec3<S> p = simsr::detail::point(V, i), q = simsr::detail::point(rest_, i);
      Mat3<S> D = Mat3<S>::Zero();
      S length = 0;
      for (Index k = adjacency_.offsets[i]; k < adjacency_.offsets[i + 1]; ++k) {
        const Index j = adjacency_.neighbors[k];
        const Vec3<S> d = p - simsr::detail::point(V, j);
        D += weights_[k] * d * (q - simsr::detail::point(rest_, j)).transpose();
        length += d.norm();
      }
      const Vec3<S> nrm = S(options_.normal_scale) * length / S(adjacency_.degree(i)) * simsr::detail::point(N, i);
      D += nrm * rest_normal_scaled_.row(i);
      T[static_cast<std::size_t>(i)] = D * rest_inverse_[static_cast<std::size_t>(i)];
    });
  }

 private:
  S edge_weight(S c, Index i, Index j) const {
    switch (options_.weights) {
      case OneRingWeights::uniform: return S(1);
      case OneRingWeights::cotangent:
        if (c < S(0))
          throw MeshError("edge", -1, "(" + std::to_string(i) + ", " + std::to_string(j) + ") has cotangent weight " +
                                          std::to_string(c) + " < 0 (obtuse pair): OneRingWeights::cotangent needs "
                                          "w ≥ 0; OneRingWeights::acap maps it to a positive weight");
        return c;
      case OneRingWeights::acap: return c <= S(0) ? std::exp(c) : S(1) + c;
    }
    return c;
  }

  OneRingFitOptions options_;
  Tris F_;
  Points<S> rest_;
  Adjacency adjacency_;
  std::vector<S> weights_;
  Points<S> rest_normal_scaled_;
  std::vector<Mat3<S>> rest_inverse_;
};

}  // namespace simsr::shell
