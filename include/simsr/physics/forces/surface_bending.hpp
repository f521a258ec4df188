#pragma once
/// \file
/// SoftDECA's bending energy (softdeca supplement eq. 3) over a triangle surface whose vertices
/// are vertices of the simulated mesh (the skin of a tet mesh):
///
///     E_curv(x) = k Σ_i A_i ‖Δx_i − R_i Δ_b x_i‖²,  R_i = argmin over SO(3)
///               = k Σ_i A_i (‖Δx_i‖ − ‖Δ_b x_i‖)²
///
/// Δ = A⁻¹L is the cotangent Laplacian L with the Voronoi areas A (mesh/cotangent_laplacian.hpp,
/// mesh/vertex_areas.hpp), both taken at the rest surface (Botsch et al. 2010; Bouaziz et al. 2014
/// §5.2): a fixed linear operator, so Δx_i is the current mean-curvature normal seen through the
/// rest discretization and Δ_b x_i its rest value. The best rotation can turn Δ_b x_i into any
/// direction, so the minimum over R is the second line: the energy keeps each vertex's curvature
/// magnitude and lets its direction follow the surface. Projective dynamics' local step is
/// p_i = ‖Δ_b x_i‖ Δx_i/‖Δx_i‖ (R_i Δ_b x_i), the constant matrix 2k Σ_i A_i Δ_iᵀΔ_i.
///
///     physics::SurfaceBending<> bend(mesh.num_vertices(), rest_positions, skin_triangles, k);  // k in J
///
/// Exact Hessian: Σ_i Δ_iᵀ h_i Δ_i with h_i = 2kA_i [ŷŷᵀ + (1 − b_i/‖y_i‖)(I − ŷŷᵀ)], y_i = Δx_i,
/// b_i = ‖Δ_b x_i‖; its tangential part is negative where ‖y_i‖ < b_i (clamped at 0 when
/// projected). It couples vertices two rings apart: those blocks lie outside a tet pattern and
/// grow the BlockHessian once. Where y_i = 0 and b_i > 0 (a vertex flattened exactly) gradient
/// and Hessian of that vertex's term are taken as 0.

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../../mesh/cotangent_laplacian.hpp"
#include "../../mesh/vertex_areas.hpp"
#include "../energy_term.hpp"
#include "detail/checks.hpp"

namespace simsr::physics {

/// k Σ_i A_i (‖Δx_i‖ − ‖Δ_b x_i‖)² over a surface's vertices (see the file comment).
template <class S = Scalar>
class SurfaceBending {
 public:
  using scalar_type = S;

  /// `rest` #V×3 positions of the whole mesh, `faces` #F×3 triangles into them (the surface),
  /// `stiffness` k ≥ 0 (J). MeshError for a face index out of range or a surface vertex with zero
  /// Voronoi area (every triangle at it degenerate); ArgumentError for a bad k or rest position.
  SurfaceBending(Index num_vertices, const Points<S>& rest, const Tris& faces, S stiffness) : n_(num_vertices) {
    detail::require_finite_matrix("SurfaceBending: rest positions", rest, n_, 3);
    for (Index f = 0; f < faces.rows(); ++f)
      for (int c = 0; c < 3; ++c)
        if (faces(f, c) < 0 || faces(f, c) >= n_)
          throw MeshError("triangle", f, "vertex index " + std::to_string(faces(f, c)) + " outside [0, " + std::to_string(n_) + ")");
    // surface vertices, in increasing order, and the surface's compact numbering
    std::vector<VIndex> local(std::size_t(n_), -1);
    for (Index f = 0; f < faces.rows(); ++f)
      for (int c = 0; c < 3; ++c) local[std::size_t(faces(f, c))] = 0;
    for (Index v = 0; v < n_; ++v)
      if (local[std::size_t(v)] == 0) {
        local[std::size_t(v)] = VIndex(vertices_.size());
        vertices_.push_back(VIndex(v));
      }
    const Index m = Index(vertices_.size());
    Points<S> V(m, 3);
    for (Index i = 0; i < m; ++i) V.row(i) = rest.row(vertices_[std::size_t(i)]);
    Tris Fl(faces.rows(), 3);
    for (Index f = 0; f < faces.rows(); ++f)
      for (int c = 0; c < 3; ++c) Fl(f, c) = local[std::size_t(faces(f, c))];
    area_ = voronoi_areas(V, Fl);
    for (Index i = 0; i < m; ++i)
      if (!(area_[i] > S(0))) throw MeshError("vertex", vertices_[std::size_t(i)], "has zero Voronoi area on the bending surface (its triangles are degenerate)");
    const Eigen::SparseMatrix<S> L = cotangent_laplacian(exec::seq, V, Fl);
    // Δ rows as CSR over the mesh's vertex numbering
    offsets_.assign(std::size_t(m) + 1, 0);
    for (Index i = 0; i < m; ++i) {
      for (typename Eigen::SparseMatrix<S>::InnerIterator it(L, i); it; ++it) {  // L symmetric: column i = row i
        cols_.push_back(vertices_[std::size_t(it.row())]);
        coef_.push_back(it.value() / area_[i]);
      }
      offsets_[std::size_t(i) + 1] = Index(cols_.size());
    }
    rest_norm_.resize(m);
    for (Index i = 0; i < m; ++i) rest_norm_[i] = laplacian(rest, i).norm();
    set_stiffness(stiffness);
  }

  Index num_vertices() const { return n_; }
  /// The surface's vertices (increasing), the Voronoi areas A_i and ‖Δ_b x_i‖ in that order.
  const std::vector<VIndex>& vertices() const { return vertices_; }
  const VecX<S>& areas() const { return area_; }
  const VecX<S>& rest_curvature() const { return rest_norm_; }
  S stiffness() const { return k_; }
  /// Changes the local–global solver's matrix: refactor it (LocalGlobalSolver::invalidate).
  void set_stiffness(S k) {
    detail::require_nonnegative("SurfaceBending: stiffness", k);
    k_ = k;
  }

  /// Δx_i of surface vertex i (its index in vertices()).
  template <class DX>
  Vec3<S> laplacian(const Eigen::MatrixBase<DX>& x, Index i) const {
    Vec3<S> y = Vec3<S>::Zero();
    for (Index e = offsets_[std::size_t(i)]; e < offsets_[std::size_t(i) + 1]; ++e) y += coef_[std::size_t(e)] * x.row(cols_[std::size_t(e)]).transpose();
    return y;
  }

  /// R_i Δ_b x_i, the local step's target for Δx_i.
  Vec3<S> project(const Points<S>& x, Index i) const {
    const Vec3<S> y = laplacian(x, i);
    const S len = y.norm();
    return len > S(0) ? Vec3<S>((rest_norm_[i] / len) * y) : Vec3<S>::Zero();
  }

  template <exec::HostPolicy P>
  S energy(P policy, const Points<S>& x) const {
    physics::detail::require_positions("SurfaceBending::energy: x", x, n_);
    return exec::parallel_reduce(
        policy, Index(vertices_.size()), S(0),
        [&](Index i) {
          const S e = laplacian(x, i).norm() - rest_norm_[i];
          return k_ * area_[i] * e * e;
        },
        [](S a, S b) { return a + b; });
  }

  /// g += Σ_i Δ_iᵀ 2kA_i (y_i − p_i): per-vertex forces in parallel, then scattered in order.
  template <exec::HostPolicy P>
  void add_gradient(P policy, const Points<S>& x, Points<S>& g) const {
    physics::detail::require_positions("SurfaceBending::add_gradient: x", x, n_);
    physics::detail::require_positions("SurfaceBending::add_gradient: g", g, n_);
    const Index m = Index(vertices_.size());
    force_.resize(m, 3);
    exec::parallel_for(policy, m, [&](Index i) {
      const Vec3<S> y = laplacian(x, i);
      const S len = y.norm();
      if (len > S(0))
        force_.row(i) = ((S(2) * k_ * area_[i] * (S(1) - rest_norm_[i] / len)) * y).transpose();
      else
        force_.row(i).setZero();
    });
    for (Index i = 0; i < m; ++i)
      for (Index e = offsets_[std::size_t(i)]; e < offsets_[std::size_t(i) + 1]; ++e) g.row(cols_[std::size_t(e)]) += coef_[std::size_t(e)] * force_.row(i);
  }

  template <exec::HostPolicy P>
  void add_hessian(P, const Points<S>& x, BlockHessian<S>& H, Definiteness d) const {
    physics::detail::require_positions("SurfaceBending::add_hessian: x", x, n_);
    for (Index i = 0; i < Index(vertices_.size()); ++i) {
      const Vec3<S> y = laplacian(x, i);
      const S len = y.norm();
      Mat3<S> h;
      if (rest_norm_[i] == S(0)) {
        h = S(2) * k_ * area_[i] * Mat3<S>::Identity();
      } else if (len > S(0)) {
        const Vec3<S> u = y / len;
        S tangential = S(1) - rest_norm_[i] / len;
        if (d == Definiteness::project) tangential = std::max(tangential, S(0));
        h = S(2) * k_ * area_[i] * (u * u.transpose() + tangential * (Mat3<S>::Identity() - u * u.transpose()));
      } else {
        continue;
      }
      scatter(H, i, h);
    }
  }

  /// The local–global solver's constant matrix 2k Σ_i A_i Δ_iᵀΔ_i.
  template <exec::HostPolicy P>
  void add_global_matrix(P, BlockHessian<S>& L) const {
    for (Index i = 0; i < Index(vertices_.size()); ++i) scatter(L, i, S(2) * k_ * area_[i] * Mat3<S>::Identity());
  }

 private:
  /// H += Δ_iᵀ h Δ_i.
  void scatter(BlockHessian<S>& H, Index i, const Mat3<S>& h) const {
    for (Index a = offsets_[std::size_t(i)]; a < offsets_[std::size_t(i) + 1]; ++a)
      for (Index b = offsets_[std::size_t(i)]; b < offsets_[std::size_t(i) + 1]; ++b)
        H.add(cols_[std::size_t(a)], cols_[std::size_t(b)], (coef_[std::size_t(a)] * coef_[std::size_t(b)]) * h);
  }

  Index n_ = 0;
  S k_ = 0;
  std::vector<VIndex> vertices_;
  VecX<S> area_, rest_norm_;
  std::vector<Index> offsets_;
  std::vector<VIndex> cols_;
  std::vector<S> coef_;
  mutable Points<S> force_;
};

static_assert(assert_energy_term<SurfaceBending<double>, double>());

}  // namespace simsr::physics
