#pragma once
/// \file
/// Hyperelastic energy of a tet mesh for any Material: E(x) = Σ_t V_t ψ(F_t) (SPEC §3; parameters
/// are per unit rest volume, so coarse and fine meshes of one body agree in bulk).
///
///     physics::ElasticEnergy<physics::NeoHookean<>> elastic(mesh, material);
///     double e = elastic.energy(exec::omp, x);
///     elastic.add_gradient(exec::omp, x, g);
///     elastic.add_hessian(exec::omp, x, H, Definiteness::exact);   // H: BlockHessian built from mesh.T
///
/// Assembly is deterministic and free of atomics, so seq and omp give bitwise-identical results:
/// element forces go to a per-tet buffer in parallel, then every vertex gathers its own in a fixed
/// order; element stiffnesses likewise block by block, or added straight into the blocks colour
/// by colour (chunks of tets of one colour share no vertex, hence no block; HessianAssembly). The
/// buffers are owned by the object and reused (const methods mutate them: one object, one thread
/// of calls at a time). The constructor's one-time setup (rest shapes, O(#T)) is sequential.

#include <algorithm>
#include <array>
#include <concepts>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../mesh/element_colouring.hpp"
#include "../mesh/tet_mesh.hpp"
#include "energy_term.hpp"
#include "detail/elastic_element_body.hpp"
#include "detail/element_stiffness_body.hpp"
#include "hessian.hpp"
#include "materials/material.hpp"
#include "tet_elements.hpp"

namespace simsr::physics {

namespace detail {
/// Materials with element data to validate offer `check(element)` (throws ArgumentError).
template <class M>
concept ChecksElements = requires(const M& m, const typename M::Element& e) { m.check(e); };
/// The ten 3×3 blocks (a, b), a ≤ b, of a symmetric element stiffness, in the order
/// (0,0) (0,1) (0,2) (0,3) (1,1) (1,2) (1,3) (2,2) (2,3) (3,3); block (b, a) is block (a, b)ᵀ.
template <class S>
using UpperBlocks12 = std::array<Mat3<S>, 10>;
/// (HasElementStiffness and upper_block, the blocks' positions: detail/element_stiffness_body.hpp.)
/// Materials usable in the local–global solver offer the stiffness of their constant matrix.
template <class M>
concept HasProjectiveStiffness = requires(const M& m) { { m.projective_stiffness() } -> std::convertible_to<typename M::scalar_type>; };
}  // namespace detail

/// How ElasticEnergy::add_hessian puts the element stiffnesses into the Hessian's blocks. Both
/// are deterministic (seq == omp bitwise) and differ only in rounding: the order of each block's
/// sum.
enum class HessianAssembly {
  /// Every tet's upper blocks to a per-tet buffer in parallel, then every block sums its tets' in
  /// tet order (the default until 2026-12-04; the coloured one's baseline).
  gather,
  /// The default. The tets cut into chunks of consecutive tets, the chunks coloured once
  /// (greedy_colouring: no two chunks of a colour share a vertex); colour by colour, chunks on any
  /// thread, each chunk's tets' stiffnesses computed and added straight into their 16 blocks in
  /// turn. No per-tet buffer (on the 73k-tet lattice 53 MB written and read again every
  /// assembly): 1.2× (one thread) to 1.4× (two) the gather's speed there (README, "Physics at the
  /// paper's LR size").
  coloured,
};

/// Σ_t V_t ψ(F_t) over the tets of a rest mesh (see the file comment).
template <class M>
class ElasticEnergy {
  static_assert(assert_material<M>());

 public:
  using S = typename detail::material_types<M>::scalar_type;
  using Element = typename detail::material_types<M>::Element;
  using material_type = M;

  /// `elements`: one per tet (fibre directions, activations), or empty for default elements.
  /// Throws MeshError for a flat or inverted rest tet (naming the first), ShapeError for an
  /// element count other than #T.
  ElasticEnergy(const TetMesh<S>& rest, M material, std::vector<Element> elements = {})
      : T_(rest.T), n_(rest.num_vertices()), material_(std::move(material)) {
    rest_ = tet_rest_data(exec::seq, rest.V, rest.T);
    if (elements.empty()) elements.resize(std::size_t(T_.rows()));
    set_elements(std::move(elements));
    D_.resize(std::size_t(T_.rows()));
    for (Index t = 0; t < T_.rows(); ++t) D_[std::size_t(t)] = shape_gradients(rest_.Dm_inv[std::size_t(t)]);
    // vertex → (tet, corner) lists for the gradient gather
    vertex_offsets_.assign(std::size_t(n_) + 1, 0);
    for (Index t = 0; t < T_.rows(); ++t)
      for (int a = 0; a < 4; ++a) ++vertex_offsets_[std::size_t(T_(t, a)) + 1];
    for (Index v = 0; v < n_; ++v) vertex_offsets_[std::size_t(v) + 1] += vertex_offsets_[std::size_t(v)];
    vertex_entries_.resize(std::size_t(4 * T_.rows()));
    std::vector<Index> fill(vertex_offsets_.begin(), vertex_offsets_.end() - 1);
    for (Index t = 0; t < T_.rows(); ++t)
      for (int a = 0; a < 4; ++a) vertex_entries_[std::size_t(fill[std::size_t(T_(t, a))]++)] = std::int32_t(4 * t + a);
  }

  Index num_vertices() const { return n_; }
  Index num_tets() const { return T_.rows(); }
  const Tets& tets() const { return T_; }
  const TetRestData<S>& rest() const { return rest_; }
  const M& material() const { return material_; }
  M& material() { return material_; }
  const std::vector<Element>& elements() const { return elements_; }
  /// Every tet's shape gradients D (4×3: F = Σ_a x_a D(a, ·)), in tet order.
  const std::vector<ShapeGradients<S>, Eigen::aligned_allocator<ShapeGradients<S>>>& element_shape_gradients() const { return D_; }
  /// The gradient's gather lists: vertex v's (tet, corner) entries 4 t + a are
  /// force_gather_entries()[force_gather_offsets()[v] .. force_gather_offsets()[v + 1]).
  const std::vector<Index>& force_gather_offsets() const { return vertex_offsets_; }
  const std::vector<std::int32_t>& force_gather_entries() const { return vertex_entries_; }
  HessianAssembly hessian_assembly() const { return assembly_; }
  Index tets_per_chunk() const { return chunk_; }
  /// Chooses add_hessian's assembly (HessianAssembly; coloured by default) and, for the coloured
  /// one, the tets per chunk (ArgumentError below 1).
  void set_hessian_assembly(HessianAssembly assembly, Index tets_per_chunk = kDefaultTetsPerChunk) {
    if (tets_per_chunk < 1) throw ArgumentError("ElasticEnergy::set_hessian_assembly: tets per chunk " + std::to_string(tets_per_chunk) + " < 1");
    assembly_ = assembly;
    if (tets_per_chunk != chunk_) {
      chunk_ = tets_per_chunk;
      colouring_ = {};
      colour_version_ = 0;
    }
  }
  /// Tets per chunk of the coloured assembly: one thread adds a chunk's consecutive tets in turn,
  /// so its blocks are touched with the mesh order's locality (coloured tet by tet, each colour's
  /// tets lie spread over the whole mesh: 1.6–1.8× the gather's time on the 73k-tet lattice).
  static constexpr Index kDefaultTetsPerChunk = 256;
  /// Replaces the per-tet data (e.g. this frame's activations); checked like the constructor's.
  void set_elements(std::vector<Element> elements) {
    if (Index(elements.size()) != T_.rows())
      throw ShapeError("ElasticEnergy: element data (one per tet)", {T_.rows()}, {Index(elements.size())});
    if constexpr (detail::ChecksElements<M>) {
      for (std::size_t t = 0; t < elements.size(); ++t) {
        try {
          material_.check(elements[t]);
        } catch (const ArgumentError& e) {
          throw ArgumentError("ElasticEnergy: tet " + std::to_string(t) + ": " + e.what());
        }
      }
    }
    elements_ = std::move(elements);
  }

  /// F of tet t at x.
  template <class DX>
  Mat3<S> deformation_gradient(const Eigen::MatrixBase<DX>& x, Index t) const {
    return physics::deformation_gradient(x, T_, t, rest_.Dm_inv[std::size_t(t)]);
  }

  /// Σ_t V_t ψ(F_t) (J).
  template <exec::HostPolicy P>
  S energy(P policy, const Points<S>& x) const {
    physics::detail::require_positions("ElasticEnergy::energy: x", x, n_);
    return exec::parallel_reduce(policy, T_.rows(), S(0), element_body<detail::ElementOutput::energy>(x), detail::Sum<S>{});
  }

  /// g += ∂E/∂x (#V×3, N).
  template <exec::HostPolicy P>
  void add_gradient(P policy, const Points<S>& x, Points<S>& g) const {
    physics::detail::require_positions("ElasticEnergy::add_gradient: x", x, n_);
    physics::detail::require_positions("ElasticEnergy::add_gradient: g", g, n_);
    forces_.resize(3, 4 * T_.rows());
    exec::parallel_for(policy, T_.rows(), element_body<detail::ElementOutput::forces>(x));
    gather_forces(policy, g);
  }

  /// E(x), and g += ∂E/∂x, in one pass over the tets (FusedEnergyGradient): each F is formed
  /// once, and a material with energy_and_stress (StrainLimit) decomposes it once.
  template <exec::HostPolicy P>
  S add_energy_gradient(P policy, const Points<S>& x, Points<S>& g) const {
    physics::detail::require_positions("ElasticEnergy::add_energy_gradient: x", x, n_);
    physics::detail::require_positions("ElasticEnergy::add_energy_gradient: g", g, n_);
    forces_.resize(3, 4 * T_.rows());
    const S e = exec::parallel_reduce(policy, T_.rows(), S(0), element_body<detail::ElementOutput::energy_and_forces>(x), detail::Sum<S>{});
    gather_forces(policy, g);
    return e;
  }

  /// Element stiffness of tet t (12×12, vertex-major), with the definiteness fix by default: the
  /// material's own element_stiffness where it has one, else through its 9×9 ∂P/∂F.
  template <class DX>
  Mat12<S> element_hessian(const Eigen::MatrixBase<DX>& x, Index t, Definiteness d = Definiteness::project) const {
    const Mat3<S> F = deformation_gradient(x, t);
    if constexpr (detail::HasElementStiffness<M>)
      return material_.element_stiffness(F, elements_[std::size_t(t)], d, D_[std::size_t(t)], rest_.volume[t]);
    else
      return element_stiffness(material_.stress_derivative(F, elements_[std::size_t(t)], d), D_[std::size_t(t)], rest_.volume[t]);
  }

  /// H += Σ_t element_hessian(x, t, d) (EnergyTerm), assembled as hessian_assembly() says; block
  /// (b, a) of a tet, b > a, is its block (a, b) transposed, so an H assembled from zero has
  /// H(j, i) = H(i, j)ᵀ exactly for i ≠ j. No allocation once the slot lists exist (built on the
  /// first call, again when H's pattern version changes). H's pattern must contain the tets'
  /// blocks, as BlockHessian(num_vertices, T) does (MeshError naming the first tet whose block is
  /// missing).
  template <exec::HostPolicy P>
  void add_hessian(P policy, const Points<S>& x, BlockHessian<S>& H, Definiteness d) const {
    physics::detail::require_positions("ElasticEnergy::add_hessian: x", x, n_);
    if (H.num_vertices() != n_) throw ShapeError("ElasticEnergy::add_hessian: Hessian vertices", {n_}, {H.num_vertices()});
    if (assembly_ == HessianAssembly::coloured)
      add_hessian_coloured(policy, x, H, d);
    else
      add_hessian_gathered(policy, x, H, d);
  }

  /// The gathered assembly's lists for H's pattern (built when stale): block slot s sums the
  /// entries [offsets[s], offsets[s+1]) of `entries`, each 16 t + 4 a + b (block (a, b) of tet t).
  /// DeviceElasticEnergy::set_hessian_pattern copies them.
  template <exec::HostPolicy P>
  std::pair<const std::vector<Index>&, const std::vector<std::int64_t>&> hessian_gather_lists(P policy, const BlockHessian<S>& H) const {
    if (H.num_vertices() != n_) throw ShapeError("ElasticEnergy::hessian_gather_lists: Hessian vertices", {n_}, {H.num_vertices()});
    if (gather_version_ != H.pattern_version()) build_gather(policy, H);
    return {gather_offsets_, gather_entries_};
  }

  /// The local–global solver's constant matrix (projective dynamics, Bouaziz et al. 2014 eq. 12):
  /// H += Σ_t V_t k (D_t ⊗ I)(D_t ⊗ I)ᵀ, k = material().projective_stiffness() (per unit volume),
  /// i.e. the Hessian of Σ_t V_t k/2 ‖F_t − const‖². For materials that offer that stiffness
  /// (StrainLimit, VolumeTarget). Sequential (once per weight set).
  template <exec::HostPolicy P>
    requires detail::HasProjectiveStiffness<M>
  void add_global_matrix(P, BlockHessian<S>& H) const {
    if (H.num_vertices() != n_) throw ShapeError("ElasticEnergy::add_global_matrix: matrix vertices", {n_}, {H.num_vertices()});
    const S k = material_.projective_stiffness();
    for (Index t = 0; t < T_.rows(); ++t) {
      const Eigen::Matrix<S, 4, 4> DD = (rest_.volume[t] * k) * D_[std::size_t(t)] * D_[std::size_t(t)].transpose();
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
          const Index s = H.slot(T_(t, a), T_(t, b));
          if (s >= 0)
            H.block(s) += DD(a, b) * Mat3<S>::Identity();
          else
            H.add(T_(t, a), T_(t, b), DD(a, b) * Mat3<S>::Identity());
        }
    }
  }

  /// Number of tets with det F ≤ 0 at x.
  template <exec::HostPolicy P>
  Index count_inverted(P policy, const Points<S>& x) const {
    physics::detail::require_positions("ElasticEnergy::count_inverted: x", x, n_);
    return exec::parallel_reduce(
        policy, T_.rows(), Index(0), [&](Index t) { return Index(deformation_gradient(x, t).determinant() <= S(0)); },
        [](Index a, Index b) { return a + b; });
  }

 private:
  /// HessianAssembly::gather.
  template <exec::HostPolicy P>
  void add_hessian_gathered(P policy, const Points<S>& x, BlockHessian<S>& H, Definiteness d) const {
    if (gather_version_ != H.pattern_version()) build_gather(policy, H);
    static_assert(sizeof(detail::UpperBlocks12<S>) == 90 * sizeof(S), "packed upper blocks");
    stiffness_.resize(std::size_t(T_.rows()));
    S* upper = stiffness_.empty() ? nullptr : stiffness_[0][0].data();
    // only the upper blocks are kept (5/8 of the 12×12: the buffer is written and read once per
    // assembly, 53 MB instead of 84 MB on the 73k-tet face lattice)
    if constexpr (detail::HasElementStiffness<M>) {  // the bodies DeviceElasticEnergy runs (detail/element_stiffness_body.hpp)
      exec::parallel_for(policy, T_.rows(), stiffness_body(x, d, upper));
    } else {  // through the material's 9×9 ∂P/∂F (host only)
      exec::parallel_for(policy, T_.rows(), [&](Index t) {
        const Mat12<S> K = element_hessian(x, t, d);
        auto& blocks = stiffness_[std::size_t(t)];
        for (int a = 0; a < 4; ++a)
          for (int b = a; b < 4; ++b) blocks[std::size_t(detail::upper_block(a, b))] = K.template block<3, 3>(3 * a, 3 * b);
      });
    }
    if (H.num_blocks() > 0)
      exec::parallel_for(policy, H.num_blocks(),
                         detail::GatherHessianBlocks<S>{gather_offsets_.data(), gather_entries_.data(), upper, H.block(0).data()});
  }

  /// HessianAssembly::coloured: the chunks of one colour share no vertex, hence no block, so
  /// each block is written by one thread, and receives its tets in (colour, tet) order whatever
  /// the thread count.
  template <exec::HostPolicy P>
  void add_hessian_coloured(P policy, const Points<S>& x, BlockHessian<S>& H, Definiteness d) const {
    if (colour_version_ != H.pattern_version()) build_colour_slots(policy, H);
    for (Index k = 0; k < colouring_.num_colours(); ++k) {
      exec::parallel_for(policy, colouring_.size(k), [&](Index i) {
        const Index chunk = colouring_.element(k, i);
        const Index end = std::min(T_.rows(), (chunk + 1) * chunk_);
        for (Index t = chunk * chunk_; t < end; ++t) {
          const Mat12<S> K = element_hessian(x, t, d);
          const Index* slot = colour_slots_.data() + 16 * t;
          for (int a = 0; a < 4; ++a) {
            H.block(slot[5 * a]) += K.template block<3, 3>(3 * a, 3 * a);
            for (int b = a + 1; b < 4; ++b) {
              const auto Kab = K.template block<3, 3>(3 * a, 3 * b);
              H.block(slot[4 * a + b]) += Kab;
              H.block(slot[4 * b + a]) += Kab.transpose();
            }
          }
        }
      });
    }
  }

  /// The element stiffness body over this object's arrays and x (element_stiffness_body.hpp; the
  /// same body DeviceElasticEnergy::add_hessian runs on the device).
  detail::ElementStiffnessBody<M> stiffness_body(const Points<S>& x, Definiteness d, S* upper) const
    requires detail::HasElementStiffness<M>
  {
    return {element_body<detail::ElementOutput::forces>(x), d, upper};
  }

  /// The per-tet body over this object's arrays and x (elastic_element_body.hpp; the same body
  /// DeviceElasticEnergy runs on the device). Forces go to forces_ (sized by the caller).
  template <detail::ElementOutput Output>
  detail::ElasticElementBody<M, Output> element_body(const Points<S>& x) const {
    static_assert(sizeof(Mat3<S>) == 9 * sizeof(S) && sizeof(ShapeGradients<S>) == 12 * sizeof(S), "packed 3x3 and 4x3 blocks");
    return {material_,
            T_.data(),
            rest_.Dm_inv.empty() ? nullptr : rest_.Dm_inv[0].data(),
            D_.empty() ? nullptr : D_[0].data(),
            rest_.volume.data(),
            elements_.data(),
            MatrixSpan<const S>{x.data(), x.rows(), 3, 3},
            forces_.data()};
  }

  /// g += every vertex's sum of its tets' forces, in a fixed order (deterministic, no atomics).
  template <exec::HostPolicy P>
  void gather_forces(P policy, Points<S>& g) const {
    exec::parallel_for(policy, n_, detail::GatherVertexForces<S>{vertex_offsets_.data(), vertex_entries_.data(), forces_.data(), MatrixSpan<S>{g.data(), g.rows(), 3, 3}});
  }

  /// slots[16 t + 4 a + b] = H's slot of block (a, b) of tet t (MeshError naming the first tet
  /// with a block H's pattern lacks).
  template <exec::HostPolicy P>
  void tet_slots(P policy, const BlockHessian<S>& H, std::vector<Index>& slots) const {
    slots.resize(std::size_t(16 * T_.rows()));
    std::vector<char> missing(std::size_t(T_.rows()), 0);
    exec::parallel_for(policy, T_.rows(), [&](Index t) {
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
          const Index s = H.slot(T_(t, a), T_(t, b));
          if (s < 0) missing[std::size_t(t)] = 1;
          slots[std::size_t(16 * t + 4 * a + b)] = s;
        }
    });
    const auto first = std::find(missing.begin(), missing.end(), char(1));
    if (first != missing.end())
      throw MeshError("tet", first - missing.begin(), "its vertex pair is missing from the Hessian pattern (build it from the same tets)");
  }

  /// The chunks (chunk_ consecutive tets each) coloured once by the vertices they touch;
  /// the slots of every tet, in tet order, whenever H's pattern changes.
  template <exec::HostPolicy P>
  void build_colour_slots(P policy, const BlockHessian<S>& H) const {
    colour_version_ = 0;  // colour_slots_ is being overwritten: matches no pattern if tet_slots throws
    const Index chunks = (T_.rows() + chunk_ - 1) / chunk_;
    if (colouring_.num_elements() != chunks) {
      std::vector<Index> offsets{0}, vertices;
      for (Index c = 0; c < chunks; ++c) {
        const auto begin = vertices.size();
        for (Index t = c * chunk_; t < std::min(T_.rows(), (c + 1) * chunk_); ++t)
          for (int a = 0; a < 4; ++a) vertices.push_back(T_(t, a));
        std::sort(vertices.begin() + std::ptrdiff_t(begin), vertices.end());
        vertices.erase(std::unique(vertices.begin() + std::ptrdiff_t(begin), vertices.end()), vertices.end());
        offsets.push_back(Index(vertices.size()));
      }
      colouring_ = greedy_colouring(offsets, vertices, n_);
    }
    tet_slots(policy, H, colour_slots_);
    colour_version_ = H.pattern_version();
  }

  template <exec::HostPolicy P>
  void build_gather(P policy, const BlockHessian<S>& H) const {
    const Index nb = H.num_blocks();
    std::vector<Index> slots;
    tet_slots(policy, H, slots);
    gather_offsets_.assign(std::size_t(nb) + 1, 0);
    for (Index s : slots) ++gather_offsets_[std::size_t(s) + 1];
    for (Index s = 0; s < nb; ++s) gather_offsets_[std::size_t(s) + 1] += gather_offsets_[std::size_t(s)];
    gather_entries_.resize(slots.size());
    std::vector<Index> fill(gather_offsets_.begin(), gather_offsets_.end() - 1);
    for (std::size_t e = 0; e < slots.size(); ++e) gather_entries_[std::size_t(fill[std::size_t(slots[e])]++)] = std::int64_t(e);
    gather_version_ = H.pattern_version();
  }

  Tets T_;
  Index n_ = 0;
  M material_;
  TetRestData<S> rest_;
  std::vector<Element> elements_;
  std::vector<ShapeGradients<S>, Eigen::aligned_allocator<ShapeGradients<S>>> D_;
  std::vector<Index> vertex_offsets_;
  std::vector<std::int32_t> vertex_entries_;
  // scratch (see the file comment)
  mutable Eigen::Matrix<S, 3, Eigen::Dynamic> forces_;
  mutable std::vector<detail::UpperBlocks12<S>> stiffness_;
  mutable std::vector<Index> gather_offsets_;
  mutable std::vector<std::int64_t> gather_entries_;
  mutable std::uint64_t gather_version_ = 0;
  HessianAssembly assembly_ = HessianAssembly::coloured;
  Index chunk_ = kDefaultTetsPerChunk;
  mutable ElementColouring colouring_;         // of the chunks, built on the first coloured assembly
  mutable std::vector<Index> colour_slots_;    // 16 per tet, in tet order
  mutable std::uint64_t colour_version_ = 0;
};

}  // namespace simsr::physics
