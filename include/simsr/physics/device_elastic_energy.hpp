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
///     BlockHessian<double> H(mesh.num_vertices(), mesh.T);             // the pattern, on the host
///     d.set_hessian_pattern(exec::omp, elastic, H);                      // its gather lists copied
///     d.add_hessian(exec::cuda, x, values, Definiteness::project);       // Span, 9 per block slot
///
/// The Hessian is ElasticEnergy's gathered assembly (HessianAssembly::gather) with its own bodies
/// (detail/element_stiffness_body.hpp): the material's element_stiffness per tet — the checked
/// closed-form SVD, whose fallback on the device is signed_svd_one_sided (Eigen's JacobiSVD is
/// host code) — then each block slot's fixed-order sum. The material must be a DeviceMaterial
/// (energy, stress and element_stiffness SIMSR_HOST_DEVICE).

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

  /// The Hessian pattern add_hessian assembles into: H's block slots and their (tet, a, b) lists
  /// (ElasticEnergy::hessian_gather_lists of `host`, this twin's host component). ShapeError for
  /// another vertex count.
  template <exec::HostPolicy P>
  void set_hessian_pattern(P policy, const ElasticEnergy<M>& host, const BlockHessian<S>& H) {
    if (host.num_vertices() != num_vertices_ || host.num_tets() != num_tets_)
      throw ShapeError("DeviceElasticEnergy::set_hessian_pattern: the host energy (vertices, tets)", {num_vertices_, num_tets_},
                       {host.num_vertices(), host.num_tets()});
    const auto [offsets, entries] = host.hessian_gather_lists(policy, H);
    hessian_offsets_ = DeviceBuffer<Index>(Span<const Index>{offsets.data(), Index(offsets.size())});
    hessian_entries_ = DeviceBuffer<std::int64_t>(Span<const std::int64_t>{entries.data(), Index(entries.size())});
    hessian_blocks_ = H.num_blocks();
    if (upper_.size() != 90 * num_tets_) upper_.resize(90 * num_tets_);
  }

  /// values += the elastic Hessian at device positions x (N×3): 9 values a block slot of the
  /// pattern set by set_hessian_pattern, column-major (BlockHessian's values), device memory.
  /// ArgumentError before set_hessian_pattern, ShapeError for another number of values.
  void add_hessian(exec::cuda_t policy, MatrixSpan<const S> x, Span<S> values, Definiteness d = Definiteness::project) const {
    static_assert(detail::HasElementStiffness<M>,
                  "DeviceElasticEnergy::add_hessian needs a material with element_stiffness (the 9x9 route is host code)");
    check("x", x.rows, x.cols);
    if (hessian_blocks_ < 0) throw ArgumentError("DeviceElasticEnergy::add_hessian: call set_hessian_pattern first");
    if (values.size != 9 * hessian_blocks_)
      throw ShapeError("DeviceElasticEnergy::add_hessian: values (9 per block slot)", {9 * hessian_blocks_}, {values.size});
    exec::parallel_for(policy, num_tets_,
                       detail::ElementStiffnessBody<M>{body<detail::ElementOutput::forces>(x), d, upper_.span().data});
    exec::parallel_for(policy, hessian_blocks_,
                       detail::GatherHessianBlocks<S>{hessian_offsets_.span().data, hessian_entries_.span().data, upper_.span().data, values.data});
  }

  Index num_vertices() const { return num_vertices_; }
  Index num_tets() const { return num_tets_; }
  /// Block slots of the Hessian pattern (-1 before set_hessian_pattern).
  Index hessian_blocks() const { return hessian_blocks_; }

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
  DeviceBuffer<Index> hessian_offsets_;
  DeviceBuffer<std::int64_t> hessian_entries_;
  Index hessian_blocks_ = -1;
  mutable DeviceBuffer<S> upper_;  // 90 per tet (the element stiffnesses' upper blocks), scratch
};

/// The device twin of an ElasticEnergy whose material is a DeviceMaterial.
template <class M>
DeviceElasticEnergy<M> to_device(const ElasticEnergy<M>& host) {
  return DeviceElasticEnergy<M>(host);
}

}  // namespace simsr::physics
#endif
