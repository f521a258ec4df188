#pragma once
/// \file
/// ElasticEnergy's device twin for exec::cuda (nvcc only): the rest data (tets, Dm⁻¹, shape
/// gradients, volumes), the element data and the gradient's gather lists copied into device
/// buffers it owns, and ElasticEnergy's own per-tet and per-vertex bodies
/// (detail/elastic_element_body.hpp) launched on the device over device positions.
///
///     physics::ElasticEnergy<physics::TeranMuscle<>> elastic(mesh, material, fibres);   // host
///     auto d = physics::to_device(elastic);                 // DeviceElasticEnergy<TeranMuscle<>>
///     double e = d.add_energy_gradient(exec::cuda, x, g);   // MatrixSpan N×3, device memory
///     d.set_elements(new_fibres);                           // this frame's activations
///
/// Energy and gradient only: the element Hessians (closed-form SVD with a Jacobi fallback, the
/// eigen-mode assembly) stay on the host. The material must be a DeviceMaterial (its energy and
/// stress SIMSR_HOST_DEVICE).

#include <vector>

#include "../core/device_buffer.hpp"
#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "detail/elastic_element_body.hpp"
#include "elastic_energy.hpp"

#if defined(__CUDACC__)
namespace simsr::physics {

/// See the file comment. Move-only (it owns device memory).
template <class M>
class DeviceElasticEnergy {
  static_assert(assert_device_material<M>());

 public:
  using S = typename M::scalar_type;
  using Element = typename M::Element;

  explicit DeviceElasticEnergy(const ElasticEnergy<M>& host)
      : material_(host.material()),
        num_vertices_(host.num_vertices()),
        num_tets_(host.num_tets()),
        tets_(Span<const VIndex>{host.tets().data(), 4 * num_tets_}),
        dm_inv_(Span<const S>{num_tets_ ? host.rest().Dm_inv[0].data() : nullptr, 9 * num_tets_}),
        shape_gradients_(Span<const S>{num_tets_ ? host.element_shape_gradients()[0].data() : nullptr, 12 * num_tets_}),
        volume_(Span<const S>{host.rest().volume.data(), num_tets_}),
        offsets_(Span<const Index>{host.force_gather_offsets().data(), Index(host.force_gather_offsets().size())}),
        entries_(Span<const std::int32_t>{host.force_gather_entries().data(), Index(host.force_gather_entries().size())}),
        forces_(12 * num_tets_) {
    static_assert(sizeof(Mat3<S>) == 9 * sizeof(S) && sizeof(ShapeGradients<S>) == 12 * sizeof(S), "packed 3x3 and 4x3 blocks");
    set_elements(host.elements());
  }

  /// Replaces the per-tet element data (this frame's activations), already checked on the host
  /// (ElasticEnergy::set_elements); ShapeError for a count other than #T.
  void set_elements(const std::vector<Element>& elements) {
    if (Index(elements.size()) != num_tets_) throw ShapeError("DeviceElasticEnergy: element data (one per tet)", {num_tets_}, {Index(elements.size())});
    const auto* bytes = reinterpret_cast<const unsigned char*>(elements.data());
    const Index n = Index(sizeof(Element)) * num_tets_;
    if (elements_.size() != n) elements_.resize(n);
    elements_.copy_from(Span<const unsigned char>{bytes, n});
  }

  /// Σ_t V_t ψ(F_t) at device positions x (N×3).
  S energy(exec::cuda_t policy, MatrixSpan<const S> x) const {
    check("x", x.rows, x.cols);
    return exec::parallel_reduce(policy, num_tets_, S(0), body<detail::ElementOutput::energy>(x), detail::Sum<S>{});
  }

  /// g += ∂E/∂x (device arrays, N×3).
  void add_gradient(exec::cuda_t policy, MatrixSpan<const S> x, MatrixSpan<S> g) const {
    check("x", x.rows, x.cols);
    check("g", g.rows, g.cols);
    exec::parallel_for(policy, num_tets_, body<detail::ElementOutput::forces>(x));
    gather(policy, g);
  }

  /// E(x), and g += ∂E/∂x, in one pass over the tets.
  S add_energy_gradient(exec::cuda_t policy, MatrixSpan<const S> x, MatrixSpan<S> g) const {
    check("x", x.rows, x.cols);
    check("g", g.rows, g.cols);
    const S e = exec::parallel_reduce(policy, num_tets_, S(0), body<detail::ElementOutput::energy_and_forces>(x), detail::Sum<S>{});
    gather(policy, g);
    return e;
  }

  Index num_vertices() const { return num_vertices_; }
  Index num_tets() const { return num_tets_; }

 private:
  template <detail::ElementOutput Output>
  detail::ElasticElementBody<M, Output> body(MatrixSpan<const S> x) const {
    return {material_,
            tets_.span().data,
            dm_inv_.span().data,
            shape_gradients_.span().data,
            volume_.span().data,
            reinterpret_cast<const Element*>(elements_.span().data),
            x,
            forces_.span().data};
  }

  void gather(exec::cuda_t policy, MatrixSpan<S> g) const {
    exec::parallel_for(policy, num_vertices_, detail::GatherVertexForces<S>{offsets_.span().data, entries_.span().data, forces_.span().data, g});
  }

  void check(const char* what, Index rows, Index cols) const {
    if (rows != num_vertices_ || cols != 3)
      throw ShapeError(std::string("DeviceElasticEnergy: ") + what + " (N×3 device array)", {num_vertices_, 3}, {rows, cols});
  }

  M material_;
  Index num_vertices_, num_tets_;
  DeviceBuffer<VIndex> tets_;
  DeviceBuffer<S> dm_inv_, shape_gradients_, volume_;
  DeviceBuffer<Index> offsets_;
  DeviceBuffer<std::int32_t> entries_;
  DeviceBuffer<unsigned char> elements_;
  mutable DeviceBuffer<S> forces_;  // 12 per tet, scratch
};

/// The device twin of an ElasticEnergy whose material is a DeviceMaterial.
template <class M>
DeviceElasticEnergy<M> to_device(const ElasticEnergy<M>& host) {
  return DeviceElasticEnergy<M>(host);
}

}  // namespace simsr::physics
#endif
