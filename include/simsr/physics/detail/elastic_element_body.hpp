#pragma once
/// \file
/// The elastic energy's per-tet and per-vertex kernel bodies (ElasticEnergy's energy, gradient and
/// fused energy+gradient): SIMSR_HOST_DEVICE functors over raw arrays, so that ElasticEnergy runs
/// them under exec::seq and exec::omp on its host arrays and DeviceElasticEnergy runs the same
/// bodies under exec::cuda on device copies (README, "Execution policies: the cuda path").
///
/// Layouts (the host containers' own): tets #T×4 row-major; Dm⁻¹ 9 scalars a tet and D (the shape
/// gradients, 4×3) 12 scalars a tet, both column-major; the element forces 12 scalars a tet (the
/// 3×4 column-major block vol·P·Dᵀ, column a the force on corner a); positions and gradients
/// N×3 row-major views.

#include <concepts>
#include <cstdint>
#include <utility>

#include <Eigen/Core>

#include "../../core/device_buffer.hpp"
#include "../../core/host_device.hpp"
#include "../../core/types.hpp"

namespace simsr::physics::detail {

/// Materials that compute ψ and P together more cheaply than apart (one SVD instead of two)
/// offer `energy_and_stress(F, element) -> std::pair<ψ, P>`.
template <class M>
concept HasEnergyAndStress = requires(const M& m, const Mat3<typename M::scalar_type>& F, const typename M::Element& e) {
  { m.energy_and_stress(F, e) } -> std::convertible_to<std::pair<typename M::scalar_type, Mat3<typename M::scalar_type>>>;
};

/// What ElasticElementBody computes for tet t: ψ alone (returns V_t ψ), forces alone (returns 0),
/// or both.
enum class ElementOutput { energy, forces, energy_and_forces };

/// Tet t's F = Ds Dm⁻¹ from positions x, V_t ψ(F) and/or its nodal forces V_t P Dᵀ (see the file
/// comment for the layouts). `material` is held by value: a device kernel receives it as a
/// parameter.
template <class M, ElementOutput Output>
struct ElasticElementBody {
  using S = typename M::scalar_type;
  using Element = typename M::Element;
  M material;
  const VIndex* tets;
  const S* dm_inv;
  const S* shape_gradients;
  const S* volume;
  const Element* elements;
  MatrixSpan<const S> x;
  S* forces;  ///< 12 per tet; unused for ElementOutput::energy

  SIMSR_HOST_DEVICE Mat3<S> deformation_gradient(Index t) const {
    const VIndex* v = tets + 4 * t;
    Mat3<S> Ds;
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) Ds(i, j) = S(x(v[j + 1], i) - x(v[0], i));
    return Ds * Eigen::Map<const Mat3<S>>(dm_inv + 9 * t);
  }

  SIMSR_HOST_DEVICE S operator()(Index t) const {
    const Mat3<S> F = deformation_gradient(t);
    const Element& e = elements[t];
    if constexpr (Output != ElementOutput::energy) {
      if constexpr (Output == ElementOutput::energy_and_forces && HasEnergyAndStress<M>) {
        const auto es = material.energy_and_stress(F, e);
        write_forces(t, es.second);
        return volume[t] * es.first;
      } else {
        write_forces(t, material.stress(F, e));
        if constexpr (Output == ElementOutput::forces)
          return S(0);
        else
          return volume[t] * material.energy(F, e);
      }
    } else {
      return volume[t] * material.energy(F, e);
    }
  }

 private:
  SIMSR_HOST_DEVICE void write_forces(Index t, const Mat3<S>& stress) const {
    Eigen::Map<Eigen::Matrix<S, 3, 4>>(forces + 12 * t).noalias() =
        volume[t] * stress * Eigen::Map<const Eigen::Matrix<S, 4, 3>>(shape_gradients + 12 * t).transpose();
  }
};

/// The energy's reduction (a named functor: a kernel's parameter types must be nameable there).
template <class S>
struct Sum {
  SIMSR_HOST_DEVICE S operator()(S a, S b) const { return a + b; }
};

/// g.row(v) += Σ of vertex v's element forces, in the fixed order of its (tet, corner) list
/// entries[offsets[v] .. offsets[v+1]) (each entry 4 t + a: column a of tet t's block, i.e. the
/// 3 scalars at forces + 3 (4 t + a)). Deterministic, no atomics.
template <class S>
struct GatherVertexForces {
  const Index* offsets;
  const std::int32_t* entries;
  const S* forces;
  MatrixSpan<S> g;

  SIMSR_HOST_DEVICE void operator()(Index v) const {
    S sum[3] = {S(0), S(0), S(0)};
    for (Index k = offsets[v]; k < offsets[v + 1]; ++k) {
      const S* f = forces + 3 * Index(entries[k]);
      for (int i = 0; i < 3; ++i) sum[i] += f[i];
    }
    for (int i = 0; i < 3; ++i) g(v, i) += sum[i];
  }
};

}  // namespace simsr::physics::detail
