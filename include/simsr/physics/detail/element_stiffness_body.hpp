#pragma once
/// \file
/// The elastic Hessian's gathered assembly as two SIMSR_HOST_DEVICE bodies (issue #17 item 5):
/// per tet its element stiffness (the material's element_stiffness on F = Ds Dm⁻¹), kept as the
/// ten upper 3×3 blocks; per block slot of the Hessian the sum of its (tet, a, b) contributions in
/// a fixed order. ElasticEnergy's HessianAssembly::gather runs them under exec::seq / exec::omp on
/// its host arrays, DeviceElasticEnergy::add_hessian under exec::cuda on device copies.
///
/// Layouts: the upper blocks 90 scalars a tet, the blocks (0,0) (0,1) (0,2) (0,3) (1,1) (1,2) (1,3)
/// (2,2) (2,3) (3,3) each 3×3 column-major (UpperBlocks12's bytes); the Hessian's values 9
/// scalars a block slot, column-major (BlockHessian's values). A gather entry is 16 t + 4 a + b:
/// block (a, b) of tet t, its transpose read for a > b.

#include <concepts>
#include <cstdint>

#include <Eigen/Core>

#include "../../core/device_buffer.hpp"
#include "../../core/host_device.hpp"
#include "../../core/types.hpp"
#include "../materials/material.hpp"
#include "elastic_element_body.hpp"

namespace simsr::physics::detail {

/// Materials that compute the element stiffness vol·(D⊗I)ᵀ ∂P/∂F (D⊗I) without forming ∂P/∂F
/// (the isotropic ones from their eigen-modes) offer `element_stiffness(F, element, d, D, vol)`.
template <class M>
concept HasElementStiffness = requires(const M& m, const Mat3<typename M::scalar_type>& F, const typename M::Element& e,
                                       Definiteness d, const ShapeGradients<typename M::scalar_type>& D, typename M::scalar_type vol) {
  { m.element_stiffness(F, e, d, D, vol) } -> std::convertible_to<Mat12<typename M::scalar_type>>;
};

/// The position of block (a, b), a ≤ b, among a tet's ten upper blocks.
SIMSR_HOST_DEVICE constexpr int upper_block(int a, int b) { return a * 4 - a * (a - 1) / 2 + (b - a); }

/// Tet t's element stiffness (the material's element_stiffness) into its ten upper blocks. The
/// arrays, positions and F are the energy's body's (ElasticElementBody; its forces unused).
/// (M must satisfy HasElementStiffness for the body to be called.)
template <class M>
struct ElementStiffnessBody {
  using S = typename M::scalar_type;
  ElasticElementBody<M, ElementOutput::forces> element;
  Definiteness definiteness;
  S* upper;  ///< 90 a tet

  SIMSR_HOST_DEVICE Mat12<S> stiffness(Index t) const {
    const Mat3<S> F = element.deformation_gradient(t);
    const ShapeGradients<S> D = Eigen::Map<const ShapeGradients<S>>(element.shape_gradients + 12 * t);
    return element.material.element_stiffness(F, element.elements[t], definiteness, D, element.volume[t]);
  }

  SIMSR_HOST_DEVICE void operator()(Index t) const {
    const Mat12<S> K = stiffness(t);
    S* out = upper + 90 * t;
    for (int a = 0; a < 4; ++a)
      for (int b = a; b < 4; ++b) Eigen::Map<Mat3<S>>(out + 9 * upper_block(a, b)) = K.template block<3, 3>(3 * a, 3 * b);
  }
};

/// Hessian block slot s += the sum of its entries[offsets[s] .. offsets[s+1]) in that order.
template <class S>
struct GatherHessianBlocks {
  const Index* offsets;
  const std::int64_t* entries;
  const S* upper;  ///< 90 a tet
  S* values;       ///< 9 a block slot

  SIMSR_HOST_DEVICE void operator()(Index s) const {
    Mat3<S> sum = Mat3<S>::Zero();
    for (Index k = offsets[s]; k < offsets[s + 1]; ++k) {
      const std::int64_t e = entries[k];
      const int a = int(e & 15) >> 2, b = int(e & 3);
      const S* tet = upper + 90 * (e >> 4);
      if (a <= b)
        sum += Eigen::Map<const Mat3<S>>(tet + 9 * upper_block(a, b));
      else
        sum += Eigen::Map<const Mat3<S>>(tet + 9 * upper_block(b, a)).transpose();
    }
    Eigen::Map<Mat3<S>>(values + 9 * s) += sum;
  }
};

}  // namespace simsr::physics::detail
