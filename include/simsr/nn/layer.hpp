#pragma once
/// \file
/// The `nn::Layer` concept: what every layer (Linear, BatchNorm1d, LeakyReLU, Sine, positional
/// encoding, pooling) provides, so models compose them as template parameters.
///
///     layer.forward(nn::Mode::train, in, out);            // exec::seq
///     layer.forward(nn::Mode::train, in, out, exec::omp); // same bits, OpenMP threads
///     store.zero_grad();
///     layer.backward(in, out, d_out, &d_in);              // += parameter gradients, d_in written
///
/// Contract (tiny-cuda-nn's shape, with the context kept inside the layer):
/// - `forward(mode, in, out[, policy])`: `in` is rows×in_features (points × channels, see
///   tensor.hpp); writes `out` (rows×out_features(in.cols())), resizing it only when its shape
///   changes, and keeps in the layer's own workspace what backward needs. Nothing is allocated
///   once the shapes are warm.
/// - `backward(in, out, d_out, d_in[, policy])`: must follow the forward of the same `in` (same
///   mode); adds the parameter gradients into the ParameterStore and writes d_in = ∂loss/∂in when
///   `d_in` is not null (overwrites it: sum branches yourself).
/// - exec::seq and exec::omp give bitwise-identical results (fixed chunks, ordered merges).
/// Why the workspace lives in the layer rather than in a returned context (DESIGN.md sketches
/// `forward(input, ctx)`): buffers reused call after call without the caller owning them; the
/// price is that one layer object serves one place in the graph (use two objects for two uses).

#include <concepts>

#include "tensor.hpp"

namespace simsr::nn {

/// Satisfied by types with the forward/backward contract above.
template <class L>
concept Layer = requires(L& layer, const L& cl, Mode mode, const Matrix<typename L::scalar_type>& in,
                         Matrix<typename L::scalar_type>& out, Matrix<typename L::scalar_type>* d_in, Index cols) {
  typename L::scalar_type;
  layer.forward(mode, in, out);
  layer.forward(mode, in, out, exec::omp);
  layer.backward(in, out, in, d_in);
  layer.backward(in, out, in, d_in, exec::omp);
  { cl.out_features(cols) } -> std::convertible_to<Index>;
};

/// static_assert helper: `static_assert(nn::assert_layer<MyLayer>());` reports a sentence.
template <class L>
constexpr bool assert_layer() {
  static_assert(Layer<L>,
                "this type is not an nn::Layer: it needs a scalar_type, forward(mode, in, out, policy = exec::seq), "
                "backward(in, out, d_out, d_in*, policy = exec::seq) and out_features(in_cols), as documented in "
                "simsr/nn/layer.hpp");
  return Layer<L>;
}

}  // namespace simsr::nn
