#pragma once
/// \file
/// Machinery shared by isotropic materials: derivatives in singular-value space turned into P and
/// ∂P/∂F (Teran et al. 2005 §5; Smith et al. 2019, "Analytic eigensystems for isotropic distortion
/// energies"), energies written in the invariants (I1, I2, J), and the C² extension of J-dependent
/// scalar functions below an inversion threshold.
///
/// Why extend functions of J rather than clamp singular values: clamping σ (PhysBAM's classic
/// inversion handling) changes the stress but not consistently the energy, so P ≠ ∂ψ/∂F at
/// inverted F and energy line searches and finite-difference checks fail there. Replacing ln J,
/// J^p by their second-order Taylor polynomial at J0 for J < J0 keeps ψ defined for every F (J ≤ 0
/// included), C², exactly consistent with P and ∂P/∂F, and with ∂ψ/∂J < 0 pushing an inverted
/// element back toward J > 0.

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "../../core/error.hpp"
#include "../../core/host_device.hpp"
#include "material.hpp"
#include "signed_svd.hpp"

namespace simsr::physics {

namespace detail {
/// Throws ArgumentError "<where>: <what> = <value> <rule>" unless `ok`.
template <class S>
void check_parameter(bool ok, const char* where, const char* what, S value, const char* rule) {
  if (ok) return;
  std::ostringstream s;
  s << where << ": " << what << " = " << value << ' ' << rule;
  throw ArgumentError(s.str());
}
}  // namespace detail

/// Value and first/second derivative of a scalar function of one variable.
template <class S = Scalar>
struct ScalarJet {
  S value;
  S first;
  S second;
};

/// f(J) for J ≥ J0, its second-order Taylor polynomial at J0 below (C² at J0). `f` maps a J ≥ J0
/// to its ScalarJet.
template <class S, class Fn>
SIMSR_HOST_DEVICE ScalarJet<S> extend_below(S J, S J0, Fn&& f) {
  if (J >= J0) return f(J);
  const ScalarJet<S> a = f(J0);
  const S d = J - J0;
  return {a.value + d * (a.first + S(0.5) * a.second * d), a.first + a.second * d, a.second};
}

/// ln J, extended below J0 (increasing for every J < J0, so −ln J penalizes inversion).
template <class S>
SIMSR_HOST_DEVICE ScalarJet<S> extended_log(S J, S J0) {
  return extend_below(J, J0, [](S x) { return ScalarJet<S>{std::log(x), S(1) / x, S(-1) / (x * x)}; });
}

/// J^p, extended below J0 (for p < 0: positive and decreasing for every J < J0).
template <class S>
SIMSR_HOST_DEVICE ScalarJet<S> extended_power(S J, S p, S J0) {
  return extend_below(J, J0, [p](S x) {
    const S v = std::pow(x, p);
    return ScalarJet<S>{v, p * v / x, p * (p - S(1)) * v / (x * x)};
  });
}

/// Derivatives of an isotropic energy ψ̂(σ) at signed singular values σ (dimension of ψ, e.g. Pa).
/// minus(k) = (g_i − g_j)/(σ_i − σ_j) and plus(k) = (g_i + g_j)/(σ_i + σ_j) for the pair (i, j)
/// with k the third index, from closed forms (no division by σ_i ∓ σ_j): the eigenvalues of the
/// flip mode U (E_ij + E_ji) Vᵀ/√2 and the twist mode U (E_ij − E_ji) Vᵀ/√2 respectively.
template <class S = Scalar>
struct PrincipalDerivatives {
  Vec3<S> g;      ///< ∂ψ̂/∂σ_i (principal stresses)
  Mat3<S> H;      ///< ∂²ψ̂/∂σ_i∂σ_j
  Vec3<S> minus;  ///< flip eigenvalues, indexed by the third index k
  Vec3<S> plus;   ///< twist eigenvalues, indexed by the third index k
};

/// P = U diag(g) Vᵀ.
template <class S>
Mat3<S> isotropic_stress(const SignedSvd<S>& svd, const Vec3<S>& g) {
  return svd.U * g.asDiagonal() * svd.V.transpose();
}

/// The positive semi-definite part of a symmetric 3×3 matrix (its negative eigenvalues set to 0).
/// A positive definite H (Sylvester: its leading minors positive; most elements' principal
/// Hessian away from compression) is returned as it is, without an eigen-decomposition.
template <class S>
SIMSR_HOST_DEVICE Mat3<S> psd_part(const Mat3<S>& H) {
  const S minor2 = H(0, 0) * H(1, 1) - H(0, 1) * H(1, 0);
  if (H(0, 0) > S(0) && minor2 > S(0) && H.determinant() > S(0)) return H;
  const Eigen::SelfAdjointEigenSolver<Mat3<S>> eig(H);
  return eig.eigenvectors() * eig.eigenvalues().cwiseMax(S(0)).asDiagonal() * eig.eigenvectors().transpose();
}

/// A flip or twist eigenvalue as `definiteness` takes it (clamped at 0 for `project`).
template <class S>
SIMSR_HOST_DEVICE S mode_eigenvalue(S e, Definiteness definiteness) {
  return definiteness == Definiteness::project ? std::max(e, S(0)) : e;
}

/// ∂vec(P)/∂vec(F) = Σ_m e_m q_m q_mᵀ over the 9 orthonormal modes q_m = vec(U M_m Vᵀ): the 3
/// modes of the diagonal block (eigenvectors of H) and the 3 flip + 3 twist modes. `project`
/// clamps every e_m at 0 (Teran et al. 2005's definiteness fix), `exact` keeps them.
template <class S>
Mat9<S> isotropic_stress_derivative(const SignedSvd<S>& svd, const PrincipalDerivatives<S>& d,
                                    Definiteness definiteness) {
  const auto q = [&](int i, int j) {  // vec(u_i v_jᵀ) = v_j ⊗ u_i
    Vec9<S> r;
    for (int c = 0; c < 3; ++c) r.template segment<3>(3 * c) = svd.V(c, j) * svd.U.col(i);
    return r;
  };
  const bool project = definiteness == Definiteness::project;
  const Mat3<S> H = project ? psd_part(d.H) : d.H;
  Eigen::Matrix<S, 9, 3> Q;
  for (int i = 0; i < 3; ++i) Q.col(i) = q(i, i);
  Mat9<S> D = Q * H * Q.transpose();
  constexpr int pairs[3][3] = {{1, 2, 0}, {0, 2, 1}, {0, 1, 2}};  // (i, j, k)
  const S r = S(1) / std::sqrt(S(2));
  for (const auto& p : pairs) {
    const Vec9<S> a = q(p[0], p[1]), b = q(p[1], p[0]);
    const Vec9<S> flip = r * (a + b), twist = r * (a - b);
    const S em = mode_eigenvalue(d.minus(p[2]), definiteness);
    const S ep = mode_eigenvalue(d.plus(p[2]), definiteness);
    D.noalias() += em * flip * flip.transpose();
    D.noalias() += ep * twist * twist.transpose();
  }
  return D;
}

/// The element stiffness vol·(D⊗I)ᵀ ∂P/∂F (D⊗I) of the ∂P/∂F above, without forming it: each
/// mode q = vec(u_i v_jᵀ) maps to the 12-vector w(a) = B(a,j) u_i with B = D V, so block (a,b) is
/// vol · U M_ab Uᵀ with (k the pair's third index, α_k = (flip_k + twist_k)/2, β_k = (flip_k − twist_k)/2)
///   M_ab(i,i) = H(i,i) B(a,i) B(b,i) + Σ_{j≠i} α_k B(a,j) B(b,j),
///   M_ab(i,j) = H(i,j) B(a,i) B(b,j) + β_k B(a,j) B(b,i)   (i ≠ j).
/// Why: the 9×9 route (isotropic_stress_derivative, then tet_elements.hpp's element_stiffness)
/// spends ~2,000 multiply-adds per tet on matrices this formula never forms (~750 here, only the
/// ten blocks a ≤ b, the others their transposes): the Newton Hessian of the 73k-tet LR face is
/// assembled four times a frame (issue #17).
template <class S>
SIMSR_HOST_DEVICE Mat12<S> isotropic_element_stiffness(const SignedSvd<S>& svd, const PrincipalDerivatives<S>& d, Definiteness definiteness,
                                     const ShapeGradients<S>& D, S vol) {
  const bool project = definiteness == Definiteness::project;
  const Mat3<S> H = project ? psd_part(d.H) : d.H;
  Vec3<S> alpha, beta;
  for (int k = 0; k < 3; ++k) {
    const S flip = mode_eigenvalue(d.minus(k), definiteness);
    const S twist = mode_eigenvalue(d.plus(k), definiteness);
    alpha(k) = S(0.5) * (flip + twist);
    beta(k) = S(0.5) * (flip - twist);
  }
  const ShapeGradients<S> B = D * svd.V;
  Mat12<S> K;
  for (int a = 0; a < 4; ++a)
    for (int b = a; b < 4; ++b) {
      Mat3<S> M;
      for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3, l = (i + 2) % 3;  // the other two indices; pair (i, j) has third index l, (i, l) has j
        M(i, i) = H(i, i) * B(a, i) * B(b, i) + alpha(l) * B(a, j) * B(b, j) + alpha(j) * B(a, l) * B(b, l);
        M(i, j) = H(i, j) * B(a, i) * B(b, j) + beta(l) * B(a, j) * B(b, i);
        M(i, l) = H(i, l) * B(a, i) * B(b, l) + beta(j) * B(a, l) * B(b, i);
      }
      const Mat3<S> block = vol * (svd.U * M * svd.U.transpose());
      if (b == a) {  // symmetric in exact arithmetic; made so in floating point
        K.template block<3, 3>(3 * a, 3 * a) = S(0.5) * (block + block.transpose());
      } else {
        K.template block<3, 3>(3 * a, 3 * b) = block;
        K.template block<3, 3>(3 * b, 3 * a) = block.transpose();
      }
    }
  return K;
}

/// The invariants of C = FᵀF used by Ψ(I1, I2, J): I1 = Σσ², I2 = Σ_{i<j} σ_i²σ_j², J = det F.
template <class S = Scalar>
struct Invariants {
  S I1;
  S I2;
  S J;
};

/// Invariants from F (no SVD).
template <class S>
SIMSR_HOST_DEVICE Invariants<S> invariants(const Mat3<S>& F) {
  const Mat3<S> C = F.transpose() * F;
  const S I1 = C.trace();
  return {I1, S(0.5) * (I1 * I1 - C.squaredNorm()), F.determinant()};
}

/// Invariants from signed singular values.
template <class S>
SIMSR_HOST_DEVICE Invariants<S> invariants(const Vec3<S>& sigma) {
  const Vec3<S> s2 = sigma.cwiseAbs2();
  return {s2.sum(), s2(0) * s2(1) + s2(0) * s2(2) + s2(1) * s2(2), sigma.prod()};
}

/// Ψ and its partials in (I1, I2, J): d = (Ψ_1, Ψ_2, Ψ_J), dd the symmetric 3×3 second partials
/// in the same order.
template <class S = Scalar>
struct InvariantPartials {
  S psi;
  Vec3<S> d;
  Mat3<S> dd;
};

/// cof F = J F⁻ᵀ = ∂J/∂F, valid for singular F too.
template <class S>
SIMSR_HOST_DEVICE Mat3<S> cofactor(const Mat3<S>& F) {
  Mat3<S> c;
  c.col(0) = F.col(1).cross(F.col(2));
  c.col(1) = F.col(2).cross(F.col(0));
  c.col(2) = F.col(0).cross(F.col(1));
  return c;
}

/// P = 2Ψ_1 F + Ψ_2 (2 I1 F − 2 F FᵀF) + Ψ_J cof F, straight from F (no SVD).
template <class S>
SIMSR_HOST_DEVICE Mat3<S> invariant_stress(const Mat3<S>& F, const Invariants<S>& inv, const Vec3<S>& d) {
  return (S(2) * d(0) + S(2) * d(1) * inv.I1) * F - S(2) * d(1) * (F * F.transpose() * F) + d(2) * cofactor(F);
}

/// Singular-value derivatives of Ψ(I1, I2, J) at σ, by the chain rule through
/// ∂I1/∂σ_i = 2σ_i, ∂I2/∂σ_i = 2σ_i(σ_j² + σ_k²), ∂J/∂σ_i = σ_jσ_k. The pair terms are
/// (g_i − g_j)/(σ_i − σ_j) = 2Ψ_1 + 2Ψ_2(σ_k² − σ_iσ_j) − Ψ_J σ_k and
/// (g_i + g_j)/(σ_i + σ_j) = 2Ψ_1 + 2Ψ_2(σ_k² + σ_iσ_j) + Ψ_J σ_k.
template <class S>
SIMSR_HOST_DEVICE PrincipalDerivatives<S> principal_from_invariants(const Vec3<S>& s, const InvariantPartials<S>& p) {
  Mat3<S> grad;  // grad(a, i) = ∂(invariant a)/∂σ_i
  Vec3<S> s2 = s.cwiseAbs2();
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    grad(0, i) = S(2) * s(i);
    grad(1, i) = S(2) * s(i) * (s2(j) + s2(k));
    grad(2, i) = s(j) * s(k);
  }
  PrincipalDerivatives<S> r;
  r.g = grad.transpose() * p.d;
  r.H = grad.transpose() * p.dd * grad;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    r.H(i, i) += S(2) * p.d(0) + S(2) * p.d(1) * (s2(j) + s2(k));
    r.H(i, j) += S(4) * p.d(1) * s(i) * s(j) + p.d(2) * s(k);
    r.H(j, i) += S(4) * p.d(1) * s(i) * s(j) + p.d(2) * s(k);
    // pair (j, k) has third index i
    r.minus(i) = S(2) * p.d(0) + S(2) * p.d(1) * (s2(i) - s(j) * s(k)) - p.d(2) * s(i);
    r.plus(i) = S(2) * p.d(0) + S(2) * p.d(1) * (s2(i) + s(j) * s(k)) + p.d(2) * s(i);
  }
  return r;
}

/// CRTP base of isotropic materials written as Ψ(I1, I2, J): `Derived::partials(Invariants)`
/// gives Ψ and its partials; the energy and P come straight from F (no SVD), ∂P/∂F through the
/// signed SVD's eigen-modes (exact, or with the definiteness fix).
template <class Derived, class S>
class InvariantMaterial {
 public:
  using scalar_type = S;
  using Element = NoElementData;

  SIMSR_HOST_DEVICE S energy(const Mat3<S>& F, const Element& = {}) const { return self().partials(invariants(F)).psi; }

  SIMSR_HOST_DEVICE Mat3<S> stress(const Mat3<S>& F, const Element& = {}) const {
    const Invariants<S> inv = invariants(F);
    return invariant_stress(F, inv, self().partials(inv).d);
  }

  Mat9<S> stress_derivative(const Mat3<S>& F, const Element&, Definiteness definiteness) const {
    const SignedSvd<S> svd = signed_svd(F);
    return isotropic_stress_derivative(svd, principal_derivatives(svd.sigma), definiteness);
  }

  /// vol·(D⊗I)ᵀ ∂P/∂F (D⊗I) straight from the eigen-modes (isotropic_element_stiffness), on the
  /// checked closed-form SVD (signed_svd_from_eigen: the Jacobi SVD where it cannot resolve F).
  SIMSR_HOST_DEVICE Mat12<S> element_stiffness(const Mat3<S>& F, const Element& e, Definiteness definiteness, const ShapeGradients<S>& D, S vol) const {
    return element_stiffness(signed_svd_from_eigen(F), e, definiteness, D, vol);
  }
  /// The same from a signed SVD of F the caller made (bench_physics's Jacobi-SVD baseline).
  SIMSR_HOST_DEVICE Mat12<S> element_stiffness(const SignedSvd<S>& svd, const Element&, Definiteness definiteness, const ShapeGradients<S>& D, S vol) const {
    return isotropic_element_stiffness(svd, principal_derivatives(svd.sigma), definiteness, D, vol);
  }

  /// Ψ's derivatives in the signed singular values σ (principal_from_invariants of its partials).
  SIMSR_HOST_DEVICE PrincipalDerivatives<S> principal_derivatives(const Vec3<S>& sigma) const {
    return principal_from_invariants(sigma, self().partials(invariants(sigma)));
  }

 private:
  SIMSR_HOST_DEVICE const Derived& self() const { return static_cast<const Derived&>(*this); }
};

}  // namespace simsr::physics
