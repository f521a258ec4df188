#pragma once
/// \file
/// Barycentric embedding of points (#Q×3, e.g. HR surface vertices) in a tet mesh (SPEC §2): each
/// point gets the tet containing it and its 4 barycentric weights; a point outside every tet (as
/// surface vertices just outside a non-conforming BCC lattice are) gets the nearest tet by exact
/// point–tet distance, with weights extrapolated (sum 1, some negative; affine fields are still
/// reproduced exactly) or clamped to the closest point of that tet.
///
///     auto emb = simsr::embed(exec::omp, lr_rest, hr_rest.V);     // Embedding<double>
///     Points<> x = simsr::deform(exec::omp, emb, lr_rest.T, lr_frame_V);      // #Q×3 deformed points
///     auto W = simsr::embedding_matrix(emb, lr_rest.T, lr_rest.num_vertices());  // Q×N, x = W·V

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../mesh/tet_mesh.hpp"
#include "point_location.hpp"

namespace simsr {

/// What to do with a point outside every tet.
enum class OutsideMode {
  extrapolate,  ///< weights of the point itself in the nearest tet (sum 1, may be negative)
  clamp,        ///< weights of the closest point of the nearest tet (all ≥ 0)
};

/// Options of embed.
struct EmbeddingOptions {
  OutsideMode outside = OutsideMode::extrapolate;
  TetLocatorOptions locator{};  ///< inside tolerance, degenerate-tet tolerance, grid cell size
};

/// Points embedded in a tet mesh. Row q: tet[q] (tet id), weights.row(q) (on the tet's 4 vertices
/// in T's order, summing to 1), inside[q] (contained within the tolerance) and distance[q] (exact
/// distance to the tet for outside points, 0 for inside ones; mesh units).
template <class S = Scalar>
struct Embedding {
  using scalar_type = S;
  IndexVector tet;                                                   ///< #Q
  Eigen::Matrix<S, Eigen::Dynamic, 4, Eigen::RowMajor> weights;      ///< #Q×4
  Eigen::Array<bool, Eigen::Dynamic, 1> inside;                      ///< #Q
  VecX<S> distance;                                                  ///< #Q

  Index size() const { return tet.size(); }
  Index num_inside() const { return inside.count(); }
  Index num_outside() const { return size() - num_inside(); }
  /// Largest distance of an outside point (0 if none).
  S max_distance() const { return distance.size() ? distance.maxCoeff() : S(0); }
};

namespace detail {
template <class D>
void embedding_check_queries(const Eigen::MatrixBase<D>& Q) {
  if (Q.cols() != 3) throw ShapeError("embed: query points", {-1, 3}, {Q.rows(), Q.cols()});
  for (Index q = 0; q < Q.rows(); ++q)
    if (!Q.row(q).allFinite()) throw ArgumentError("embed: query point " + std::to_string(q) + " has a non-finite coordinate");
}
}  // namespace detail

/// Embeds the points Q (#Q×3) with a prebuilt locator. seq and omp give identical results (each
/// point is computed independently; ties go to the lowest tet id). Throws ShapeError for Q not
/// #Q×3, ArgumentError naming the first non-finite point.
template <exec::HostPolicy P, class S, class DQ>
Embedding<S> embed(P policy, const TetLocator<S>& locator, const Eigen::MatrixBase<DQ>& Q,
                   OutsideMode outside = OutsideMode::extrapolate) {
  detail::embedding_check_queries(Q);
  if (locator.num_tets() == 0) throw MeshError("tet mesh", -1, "empty (no tets): nothing to embed into");
  Embedding<S> e;
  const Index n = Q.rows();
  e.tet.resize(n);
  e.weights.resize(n, 4);
  e.inside.resize(n);
  e.distance.resize(n);
  exec::parallel_for(policy, n, [&](Index q) {
    const Vec3<S> p(S(Q(q, 0)), S(Q(q, 1)), S(Q(q, 2)));
    detail::Vec4<S> w;
    Index t = locator.locate(p, w);
    S dist = S(0);
    const bool in = t >= 0;
    if (!in) {
      const NearestTet<S> nt = locator.nearest(p);
      t = nt.tet;
      dist = nt.distance;
      if (outside == OutsideMode::clamp)
        locator.distance(t, p, &w);
      else
        w = locator.barycentric(t, p);
    }
    e.tet[q] = VIndex(t);
    e.weights.row(q) = w.transpose();
    e.inside[q] = in;
    e.distance[q] = dist;
  });
  return e;
}

/// Embeds the points Q (#Q×3) in `mesh`: builds a TetLocator (MeshError for an empty mesh or a
/// degenerate tet, naming it) and embeds under `policy`.
template <exec::HostPolicy P, class S, class DQ>
Embedding<S> embed(P policy, const TetMesh<S>& mesh, const Eigen::MatrixBase<DQ>& Q, const EmbeddingOptions& options = {}) {
  detail::embedding_check_queries(Q);
  const TetLocator<S> locator(mesh, options.locator);
  return embed(policy, locator, Q, options.outside);
}

namespace detail {
/// Checks that every embedded point's tet exists in T and indexes one of `num_vertices` vertices.
template <class S>
void embedding_check_tets(const char* what, const Embedding<S>& e, const Tets& T, Index num_vertices) {
  if (e.weights.rows() != e.size()) throw ShapeError(std::string(what) + ": embedding weights", {e.size(), 4}, {e.weights.rows(), 4});
  for (Index q = 0; q < e.size(); ++q) {
    const Index t = e.tet[q];
    if (t < 0 || t >= T.rows())
      throw ArgumentError(std::string(what) + ": point " + std::to_string(q) + " refers to tet " + std::to_string(t) + ", mesh has " +
                          std::to_string(T.rows()));
    for (int k = 0; k < 4; ++k)
      if (T(t, k) < 0 || T(t, k) >= num_vertices)
        throw MeshError("tet", t, "vertex index " + std::to_string(T(t, k)) + " outside [0, " + std::to_string(num_vertices) + ")");
  }
}
}  // namespace detail

/// Deformed positions of the embedded points, x_q = Σ_k w_qk V[T(tet_q, k)]: #Q×3. `T` is the
/// embedding mesh's #T×4 tets, `V` (#V×3) its deformed vertices (or any per-vertex 3-vector
/// field: displacements in give displacements out).
template <exec::HostPolicy P, class S, class DV>
Points<S> deform(P policy, const Embedding<S>& e, const Tets& T, const Eigen::MatrixBase<DV>& V) {
  if (V.cols() != 3) throw ShapeError("deform: deformed vertices", {-1, 3}, {V.rows(), V.cols()});
  detail::embedding_check_tets("deform", e, T, V.rows());
  Points<S> X(e.size(), 3);
  exec::parallel_for(policy, e.size(), [&](Index q) {
    const Index t = e.tet[q];
    Vec3<S> x = Vec3<S>::Zero();
    for (int k = 0; k < 4; ++k) x += e.weights(q, k) * V.row(T(t, k)).transpose().template cast<S>();
    X.row(q) = x.transpose();
  });
  return X;
}

/// The embedding as a row-major Q×N sparse matrix W (4 entries per row, explicit zeros kept for a
/// fixed pattern), so that deform(e, T, V) == W·V for any #N×3 V.
template <class S>
Eigen::SparseMatrix<S, Eigen::RowMajor, VIndex> embedding_matrix(const Embedding<S>& e, const Tets& T, Index num_vertices) {
  detail::embedding_check_tets("embedding_matrix", e, T, num_vertices);
  Eigen::SparseMatrix<S, Eigen::RowMajor, VIndex> W(e.size(), num_vertices);
  W.reserve(Eigen::Matrix<VIndex, Eigen::Dynamic, 1>::Constant(e.size(), 4));
  for (Index q = 0; q < e.size(); ++q) {
    const Index t = e.tet[q];
    for (int k = 0; k < 4; ++k) W.insert(q, T(t, k)) = e.weights(q, k);
  }
  W.makeCompressed();
  return W;
}

}  // namespace simsr
