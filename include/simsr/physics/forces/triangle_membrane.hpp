#pragma once
/// \file
/// The as-rigid-as-possible membrane of a triangle surface (cloth's stretching; Bouaziz et al.
/// 2014 §5, Liu et al. 2013), resolution-independent because it is integrated over area:
///
///     E(x) = k Σ_t A_t ‖F_t − R_t‖²_F,   F_t = [x₁ − x₀, x₂ − x₀] D_t⁻¹ (3×2),   R_t = U Vᵀ
///
/// A_t the rest area, D_t the rest edges in the triangle's own 2-D frame (so F_t = the 3×2
/// deformation gradient), F = U Σ Vᵀ its thin SVD and R_t the closest matrix with orthonormal
/// columns (k in J/m² = N/m). Since R_t minimizes ‖F − R‖, ∂E/∂F = 2kA(F − R) (the envelope
/// theorem); the projective-dynamics projection is R_t itself and the constant matrix
/// 2k Σ_t A_t G_tᵀG_t (G_t: x ↦ F_t).
///
/// Exact Hessian: ∂²E/∂F² = 2kA(I − ∂R/∂F) with R = F (FᵀF)^{-1/2}: dR = dF P + F dP,
/// P = (FᵀF)^{-1/2}, dP = −P X P where X solves X P⁻¹ + P⁻¹ X = dFᵀF + FᵀdF (a 2×2 Sylvester
/// equation, diagonal in FᵀF's eigenbasis). It is indefinite where the triangle is compressed
/// (σ < 1); Definiteness::project clamps the eigenvalues of the 6×6 F-space Hessian at 0, which
/// keeps the x-space blocks PSD. A triangle collapsed to rank < 2 gets the PSD 2kA·I in F-space.
///
///     physics::TriangleMembrane<> stretch(V.rows(), rest, F, 200.0);   // k = 200 N/m

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <string>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../energy_term.hpp"
#include "../hessian.hpp"
#include "detail/checks.hpp"

namespace simsr::physics {

template <class S = Scalar>
class TriangleMembrane {
 public:
  using scalar_type = S;

  /// `rest` #V×3 (the mesh's rest positions), `faces` #F×3, stiffness k ≥ 0 (N/m). MeshError for
  /// an index out of range or a degenerate rest triangle; ArgumentError for bad k or positions.
  TriangleMembrane(Index num_vertices, const Points<S>& rest, const Tris& faces, S stiffness) : n_(num_vertices), F_(faces), k_(stiffness) {
    detail::require_finite_matrix("TriangleMembrane: rest positions", rest, n_, 3);
    detail::require_nonnegative("TriangleMembrane: stiffness", stiffness);
    const Index m = faces.rows();
    Dinv_.resize(static_cast<std::size_t>(m));
    area_.resize(m);
    for (Index f = 0; f < m; ++f) {
      for (int c = 0; c < 3; ++c)
        if (faces(f, c) < 0 || faces(f, c) >= n_)
          throw MeshError("triangle", f, "vertex index " + std::to_string(faces(f, c)) + " outside [0, " + std::to_string(n_) + ")");
      const Vec3<S> e1 = rest.row(faces(f, 1)) - rest.row(faces(f, 0)), e2 = rest.row(faces(f, 2)) - rest.row(faces(f, 0));
      const S a2 = e1.cross(e2).norm();
      if (!(a2 > S(1e-14) * e1.squaredNorm() + S(0)) || !(e1.norm() > S(0)))
        throw MeshError("triangle", f, "is degenerate in the rest shape (zero area): no membrane strain is defined");
      // the triangle's own frame: u along e1, v in the plane
      const Vec3<S> u = e1.normalized(), v = (e2 - e2.dot(u) * u).normalized();
      Eigen::Matrix<S, 2, 2> D;
      D << e1.dot(u), e2.dot(u), e1.dot(v), e2.dot(v);
      Dinv_[static_cast<std::size_t>(f)] = D.inverse();
      area_[f] = a2 / S(2);
    }
  }

  S stiffness() const { return k_; }
  const VecX<S>& rest_areas() const { return area_; }

  template <exec::HostPolicy P>
  S energy(P policy, const Points<S>& x) const {
    detail::require_positions("TriangleMembrane::energy: x", x, n_);
    return exec::parallel_reduce(
        policy, F_.rows(), S(0),
        [&](Index f) {
          const M32 Fm = deformation_gradient(x, f);
          return k_ * area_[f] * (Fm - closest_orthonormal(Fm)).squaredNorm();
        },
        [](S a, S b) { return a + b; });
  }

  /// g += ∂E/∂x: per-triangle corner forces in parallel, scattered in triangle order.
  template <exec::HostPolicy P>
  void add_gradient(P policy, const Points<S>& x, Points<S>& g) const {
    detail::require_positions("TriangleMembrane::add_gradient: x", x, n_);
    detail::require_positions("TriangleMembrane::add_gradient: g", g, n_);
    corner_.resize(F_.rows(), 9);
    exec::parallel_for(policy, F_.rows(), [&](Index f) {
      const M32 Fm = deformation_gradient(x, f);
      const M32 dEdF = S(2) * k_ * area_[f] * (Fm - closest_orthonormal(Fm));
      const M32 G = dEdF * Dinv_[static_cast<std::size_t>(f)].transpose();  // ∂E/∂[x₁−x₀, x₂−x₀]
      corner_.row(f) << -(G.col(0) + G.col(1)).transpose(), G.col(0).transpose(), G.col(1).transpose();
    });
    for (Index f = 0; f < F_.rows(); ++f)
      for (int c = 0; c < 3; ++c) g.row(F_(f, c)) += corner_.row(f).template segment<3>(3 * c);
  }

  template <exec::HostPolicy P>
  void add_hessian(P, const Points<S>& x, BlockHessian<S>& H, Definiteness d) const {
    detail::require_positions("TriangleMembrane::add_hessian: x", x, n_);
    for (Index f = 0; f < F_.rows(); ++f) {
      const M6 HF = hessian_F(deformation_gradient(x, f), d) * (S(2) * k_ * area_[f]);
      scatter(H, f, HF);
    }
  }

  /// The local–global solver's constant matrix 2k Σ_t A_t G_tᵀG_t (the Hessian at R = const).
  template <exec::HostPolicy P>
  void add_global_matrix(P, BlockHessian<S>& L) const {
    for (Index f = 0; f < F_.rows(); ++f) scatter(L, f, M6(M6::Identity() * (S(2) * k_ * area_[f])));
  }

  /// The 6×6 ∂²/∂F² of ‖F − R(F)‖² / 2 = (I − ∂R/∂F), F's entries in column-major order
  /// (F(0,0), F(1,0), F(2,0), F(0,1), …); projected to PSD when d = project.
  static Eigen::Matrix<S, 6, 6> hessian_F(const Eigen::Matrix<S, 3, 2>& Fm, Definiteness d) {
    M6 H = M6::Identity();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<S, 2, 2>> es(Fm.transpose() * Fm);
    const Eigen::Matrix<S, 2, 1> lam = es.eigenvalues();
    if (!(lam.minCoeff() > S(1e-24) * std::max(S(1), lam.maxCoeff()))) return H;  // collapsed: PSD stand-in
    const Eigen::Matrix<S, 2, 2> Q = es.eigenvectors();
    const Eigen::Matrix<S, 2, 1> sig = lam.cwiseSqrt();
    const Eigen::Matrix<S, 2, 2> Pm = Q * sig.cwiseInverse().asDiagonal() * Q.transpose();
    for (int k = 0; k < 6; ++k) {
      M32 dF = M32::Zero();
      dF(k % 3, k / 3) = S(1);
      const Eigen::Matrix<S, 2, 2> dC = dF.transpose() * Fm + Fm.transpose() * dF;
      Eigen::Matrix<S, 2, 2> X = Q.transpose() * dC * Q;  // in the eigenbasis
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) X(i, j) /= sig[i] + sig[j];
      X = Q * X * Q.transpose();
      const M32 dR = dF * Pm - Fm * (Pm * X * Pm);
      const M32 col = dF - dR;
      H.col(k) = Eigen::Map<const Eigen::Matrix<S, 6, 1>>(col.data());
    }
    H = S(0.5) * (H + H.transpose()).eval();
    if (d == Definiteness::project) {
      const Eigen::SelfAdjointEigenSolver<M6> eh(H);
      H = eh.eigenvectors() * eh.eigenvalues().cwiseMax(S(0)).asDiagonal() * eh.eigenvectors().transpose();
    }
    return H;
  }

 private:
  using M32 = Eigen::Matrix<S, 3, 2>;
  using M6 = Eigen::Matrix<S, 6, 6>;

  M32 deformation_gradient(const Points<S>& x, Index f) const {
    M32 Ds;
    Ds.col(0) = (x.row(F_(f, 1)) - x.row(F_(f, 0))).transpose();
    Ds.col(1) = (x.row(F_(f, 2)) - x.row(F_(f, 0))).transpose();
    return Ds * Dinv_[static_cast<std::size_t>(f)];
  }

  static M32 closest_orthonormal(const M32& Fm) {
    const Eigen::JacobiSVD<M32> svd(Fm, Eigen::ComputeFullU | Eigen::ComputeFullV);  // fixed size: full U (3×3)
    return svd.matrixU().template leftCols<2>() * svd.matrixV().transpose();
  }

  /// H += Gᵀ HF G for triangle f, G the 6×9 map from its corners to F's entries.
  void scatter(BlockHessian<S>& H, Index f, const M6& HF) const {
    // ∂F(r, c)/∂x_corner(r) = W(corner, c): W = [−(Dinv row 0 + row 1); Dinv rows] over corners
    const Eigen::Matrix<S, 2, 2>& Di = Dinv_[static_cast<std::size_t>(f)];
    Eigen::Matrix<S, 3, 2> W;
    W.row(0) = -(Di.row(0) + Di.row(1));
    W.row(1) = Di.row(0);
    W.row(2) = Di.row(1);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        Mat3<S> block = Mat3<S>::Zero();
        for (int ca = 0; ca < 2; ++ca)
          for (int cb = 0; cb < 2; ++cb) block += (W(a, ca) * W(b, cb)) * HF.template block<3, 3>(3 * ca, 3 * cb);
        H.add(F_(f, a), F_(f, b), block);
      }
  }

  Index n_ = 0;
  Tris F_;
  S k_ = 0;
  std::vector<Eigen::Matrix<S, 2, 2>> Dinv_;
  VecX<S> area_;
  mutable Eigen::Matrix<S, Eigen::Dynamic, 9, Eigen::RowMajor> corner_;
};

static_assert(assert_energy_term<TriangleMembrane<double>, double>());

}  // namespace simsr::physics
