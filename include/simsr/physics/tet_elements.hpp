#pragma once
/// \file
/// Linear tetrahedral elements: the rest-shape data every FEM term needs (Dm⁻¹ and rest volume,
/// Sifakis & Barbič 2012 §4) and the maps between vertex positions, F, forces and stiffness.
///
///     auto rest = physics::tet_rest_data(exec::seq, mesh.V, mesh.T);   // throws MeshError on a flat/inverted rest tet
///     Mat3<> F  = physics::deformation_gradient(x, mesh.T, t, rest.Dm_inv[t]);
///
/// F = Ds Dm⁻¹ with Ds = [x1−x0, x2−x0, x3−x0]; writing D (4×3) for the rows (−1ᵀDm⁻¹; Dm⁻¹),
/// F(i,j) = Σ_a x_a[i] D(a,j), so the element force is vol·P·Dᵀ and the element stiffness is
/// vol·(D ⊗ I)ᵀ ∂P/∂F (D ⊗ I).

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "materials/material.hpp"

namespace simsr::physics {

/// Rest data of #T tets.
template <class S = Scalar>
struct TetRestData {
  std::vector<Mat3<S>, Eigen::aligned_allocator<Mat3<S>>> Dm_inv;  ///< #T inverse rest edge matrices
  VecX<S> volume;                                                  ///< #T rest volumes (m³), all > 0
  Index size() const { return volume.size(); }
};

/// Computes Dm⁻¹ and the rest volume of every tet. A tet whose rest volume is not positive
/// (inverted, or flat below `relative_tolerance`·(mean edge length)³) is a MeshError naming it
/// (under exec::seq the first such tet; under exec::omp any one).
template <exec::HostPolicy P, class DV>
TetRestData<typename DV::Scalar> tet_rest_data(P policy, const Eigen::MatrixBase<DV>& V, const Tets& T,
                                               double relative_tolerance = 1e-12) {
  using S = typename DV::Scalar;
  if (V.cols() != 3) throw ShapeError("tet_rest_data: V", {-1, 3}, {V.rows(), V.cols()});
  TetRestData<S> r;
  r.Dm_inv.resize(std::size_t(T.rows()));
  r.volume.resize(T.rows());
  exec::parallel_for(policy, T.rows(), [&](Index t) {
    for (int a = 0; a < 4; ++a)
      if (T(t, a) < 0 || T(t, a) >= V.rows())
        throw MeshError("tet", t, "vertex index " + std::to_string(T(t, a)) + " out of range [0, " + std::to_string(V.rows()) + ")");
    Mat3<S> Dm;
    S edge = 0;
    for (int j = 0; j < 3; ++j) {
      Dm.col(j) = (V.row(T(t, j + 1)) - V.row(T(t, 0))).transpose();
      edge += Dm.col(j).norm();
    }
    edge /= S(3);
    const S det = Dm.determinant();
    if (!std::isfinite(double(det)))
      throw MeshError("tet", t, "rest position is not finite");
    if (!(det > S(relative_tolerance) * edge * edge * edge))
      throw MeshError("tet", t, det < 0 ? "inverted in the rest shape (signed volume " + std::to_string(double(det) / 6) + ")"
                                        : "degenerate in the rest shape (volume " + std::to_string(double(det) / 6) + ")");
    r.Dm_inv[std::size_t(t)] = Dm.inverse();
    r.volume[t] = det / S(6);
  });
  return r;
}

/// F of tet t at positions x (#V×3).
template <class DX, class S>
Mat3<S> deformation_gradient(const Eigen::MatrixBase<DX>& x, const Tets& T, Index t, const Mat3<S>& Dm_inv) {
  Mat3<S> Ds;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) Ds(i, j) = S(x(T(t, j + 1), i) - x(T(t, 0), i));
  return Ds * Dm_inv;
}

/// D (4×3): F(i,j) = Σ_a x_a[i] D(a,j). Row 0 is minus the column sums of Dm⁻¹'s rows.
template <class S>
Eigen::Matrix<S, 4, 3> shape_gradients(const Mat3<S>& Dm_inv) {
  Eigen::Matrix<S, 4, 3> D;
  D.template bottomRows<3>() = Dm_inv;
  D.row(0) = -Dm_inv.colwise().sum();
  return D;
}

/// Element stiffness vol·(D⊗I)ᵀ A (D⊗I) for A = ∂vec(P)/∂vec(F) (column-major vec): block (a,b)
/// is vol·Σ_jl D(a,j) D(b,l) A[3j:3j+3, 3l:3l+3].
template <class S>
Mat12<S> element_stiffness(const Mat9<S>& A, const Eigen::Matrix<S, 4, 3>& D, S vol) {
  // AD(:, 3b+k) = Σ_l A(:, 3l+k) D(b,l): 9×12
  Eigen::Matrix<S, 9, 12> AD;
  for (int b = 0; b < 4; ++b)
    AD.template middleCols<3>(3 * b) = D(b, 0) * A.template middleCols<3>(0) + D(b, 1) * A.template middleCols<3>(3) +
                                       D(b, 2) * A.template middleCols<3>(6);
  Mat12<S> K;
  for (int a = 0; a < 4; ++a)
    K.template middleRows<3>(3 * a) = vol * (D(a, 0) * AD.template middleRows<3>(0) + D(a, 1) * AD.template middleRows<3>(3) +
                                             D(a, 2) * AD.template middleRows<3>(6));
  return K;
}

}  // namespace simsr::physics
