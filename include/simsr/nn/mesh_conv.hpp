#pragma once
/// \file
/// Mesh convolution on vertices (Chen et al. 2023 supplement Eq. 5; Duvenaud et al. 2015):
///
///     f_i' = W_point f_i + W_neighbor · (1/D_i) Σ_{j∈N(i)} f_j + b
///
/// over a fixed mesh graph (one-ring adjacency, symmetric). Input rows are B·V vertices, point-major
/// per batch item (row b·V + i is vertex i of item b, tensor.hpp's layout), columns the channels.
///
///     nn::MeshConv<float> conv(store, "enc.conv1", vertex_adjacency(F), 9, 64, rng);
///     conv.forward(exec::omp, nn::Mode::train, features, h);   // (B·V)×9 → (B·V)×64

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "../mesh/topology.hpp"
#include "layer.hpp"
#include "linear.hpp"

namespace simsr::nn {

/// Eq. 5 as two Linear maps (tensors `<name>.point.weight`, `<name>.point.bias`,
/// `<name>.neighbor.weight`) of the vertex's own features and of its neighbours' mean.
template <class S = float>
class MeshConv {
 public:
  using scalar_type = S;

  /// `graph`: the mesh's vertex adjacency (mesh/topology.hpp), which must be symmetric (j ∈ N(i)
  /// ⟺ i ∈ N(j)) and give every vertex a neighbour: ArgumentError otherwise. Weights drawn as
  /// PyTorch's nn.Linear defaults.
  MeshConv(ParameterStore<S>& store, std::string name, Adjacency graph, Index in, Index out, Rng& rng)
      : graph_(std::make_shared<const Adjacency>(std::move(graph))),
        point_(store, name + ".point", in, out, rng),
        neighbor_(store, name + ".neighbor", in, out, rng, {.bias = false}),
        where_("nn::MeshConv '" + name + "'") {
    const Adjacency& A = *graph_;
    for (Index i = 0; i < A.num_vertices(); ++i) {
      if (A.degree(i) == 0) throw ArgumentError(where_ + ": vertex " + std::to_string(i) + " has no neighbour");
      for (const VIndex j : A[i]) {
        bool back = false;
        for (const VIndex k : A[j]) back = back || k == i;
        if (!back)
          throw ArgumentError(where_ + ": adjacency not symmetric (" + std::to_string(j) + " in N(" + std::to_string(i) +
                              ") but not the reverse)");
      }
    }
  }

  Index num_vertices() const { return graph_->num_vertices(); }
  Index in_features() const { return point_.in_features(); }
  Index out_features(Index = -1) const { return point_.out_features(); }
  Linear<S>& point() { return point_; }
  Linear<S>& neighbor() { return neighbor_; }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& in, Matrix<S>& out) {
    check_rows(in.rows());
    mean_of_neighbors(policy, in, mean_);
    point_.forward(policy, mode, in, out);
    neighbor_.forward(policy, mode, mean_, from_neighbors_);
    out += from_neighbors_;
  }

  /// Both maps' gradients; d_in = W_pointᵀ-part + the neighbour mean's transpose applied to the
  /// W_neighbor-part, a gather over the (symmetric) graph: d_in_j += Σ_{i∈N(j)} g_i / D_i.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>& out, const ConstView<S>& d_out, Matrix<S>* d_in) {
    check_rows(in.rows());
    point_.backward(policy, in, out, d_out, d_in);
    neighbor_.backward(policy, mean_, from_neighbors_, d_out, d_in ? &d_mean_ : nullptr);
    if (!d_in) return;
    const Adjacency& A = *graph_;
    const Index V = A.num_vertices(), R = in.rows();
    const Index nc = exec::chunk_count(R, product_chunks);
    const Index C = in.cols();
    exec::for_chunks(policy, R, nc, exec::worker_count(policy, nc), [&](Index, Index, Index lo, Index hi) {
      // raw rows (d_in and d_mean_ are packed R×C): Eigen's row expressions of a few channels
      // cost more in bookkeeping than in adds; the same operations in the same order
      for (Index r = lo; r < hi; ++r) {
        const Index base = r - r % V, j = r % V;
        S* d = d_in->data() + r * C;
        for (const VIndex i : A[j]) {
          const S* g = d_mean_.data() + (base + i) * C;
          const S deg = S(A.degree(i));
          for (Index c = 0; c < C; ++c) d[c] += g[c] / deg;
        }
      }
    });
  }

 private:
  void check_rows(Index rows) const {
    if (rows % num_vertices() != 0)
      throw ShapeError(where_ + ": input rows (batch × vertices)", {-1, num_vertices()}, {rows, num_vertices()});
  }

  template <exec::HostPolicy Policy>
  void mean_of_neighbors(Policy policy, const ConstView<S>& in, Matrix<S>& M) const {
    const Adjacency& A = *graph_;
    const Index V = A.num_vertices(), R = in.rows();
    ensure_shape(M, R, in.cols());
    const Index nc = exec::chunk_count(R, product_chunks);
    const Index C = in.cols(), ld = in.outerStride();
    exec::for_chunks(policy, R, nc, exec::worker_count(policy, nc), [&](Index, Index, Index lo, Index hi) {
      for (Index r = lo; r < hi; ++r) {  // raw rows, as in backward
        const Index base = r - r % V, i = r % V;
        S* m = M.data() + r * C;
        for (Index c = 0; c < C; ++c) m[c] = S(0);
        for (const VIndex j : A[i]) {
          const S* x = in.data() + (base + j) * ld;
          for (Index c = 0; c < C; ++c) m[c] += x[c];
        }
        const S deg = S(A.degree(i));
        for (Index c = 0; c < C; ++c) m[c] /= deg;
      }
    });
  }

  std::shared_ptr<const Adjacency> graph_;
  Linear<S> point_, neighbor_;
  std::string where_;
  Matrix<S> mean_, from_neighbors_, d_mean_;
};
static_assert(assert_layer<MeshConv<float>>());

}  // namespace simsr::nn
