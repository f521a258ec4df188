#pragma once
/// \file
/// The `nn::Layer` concept: what every layer (Linear, BatchNorm1d, LeakyReLU, Sine, Dropout,
/// positional encoding, pooling, graph features, Mlp, EdgeConv, …) provides, so models compose
/// them as template parameters (nn::Sequential, sequential.hpp).
///
///     layer.forward(exec::seq, nn::Mode::train, in, out);   // the policy first, always named
///     layer.forward(exec::omp, nn::Mode::train, in, out);   // same bits, OpenMP threads
///     store.zero_grad();
///     layer.backward(exec::omp, in, out, d_out, &d_in);     // += parameter gradients, d_in written
///
/// Contract (tiny-cuda-nn's shape, with the context kept inside the layer):
/// - `forward(policy, mode, in, out)`: `in` is rows×in_features (points × channels, see
///   tensor.hpp); writes `out` (rows×out_features(in.cols())), resizing it only when its shape
///   changes, and keeps in the layer's own workspace what backward needs. Nothing is allocated
///   once the shapes are warm.
/// - `backward(policy, in, out, d_out, d_in)`: must follow the forward of the same `in` (same
///   mode); adds the parameter gradients into the ParameterStore and writes d_in = ∂loss/∂in when
///   `d_in` is not null (overwrites it: sum branches yourself).
/// - The policy (exec::seq or exec::omp) comes first and has no default; exec::seq and exec::omp
///   give bitwise-identical results (fixed chunks, ordered merges). No layer is templated on a
///   policy and no constructor takes one.
/// Why the workspace lives in the layer rather than in a returned context (DESIGN.md sketches
/// `forward(input, ctx)`): buffers reused call after call without the caller owning them; the
/// price is that one layer object serves one place in the graph (use two objects for two uses).

#include <concepts>

#include "tensor.hpp"

namespace simsr::nn {

namespace detail {

template <class L>
concept NamesLayerScalar = requires { typename L::scalar_type; };

template <class L>
concept ForwardsPolicyFirst = NamesLayerScalar<L> &&
    requires(L& layer, Mode mode, const Matrix<typename L::scalar_type>& in, Matrix<typename L::scalar_type>& out) {
      layer.forward(exec::seq, mode, in, out);
      layer.forward(exec::omp, mode, in, out);
    };

template <class L>
concept BackwardsPolicyFirst = NamesLayerScalar<L> &&
    requires(L& layer, const Matrix<typename L::scalar_type>& m, Matrix<typename L::scalar_type>* d_in) {
      layer.backward(exec::seq, m, m, m, d_in);
      layer.backward(exec::omp, m, m, m, d_in);
    };

template <class L>
concept ReportsOutFeatures = requires(const L& layer, Index cols) {
  { layer.out_features(cols) } -> std::convertible_to<Index>;
};

template <class>
inline constexpr bool layer_check_failed = false;

}  // namespace detail

/// Satisfied by types with the forward/backward contract above: a `scalar_type`,
/// `forward(policy, mode, in, out)` and `backward(policy, in, out, d_out, d_in*)` for exec::seq
/// and exec::omp, and `out_features(in_cols) const`.
template <class L>
concept Layer = detail::NamesLayerScalar<L> && detail::ForwardsPolicyFirst<L> && detail::BackwardsPolicyFirst<L> &&
                detail::ReportsOutFeatures<L>;

/// `static_assert(nn::assert_layer<L>())`: a type that is not a Layer stops the build with one
/// sentence naming the first thing it lacks (and nothing else: the function returns true once its
/// own assertion has spoken). Library templates over layers (nn::Sequential) check with it.
template <class L>
constexpr bool assert_layer() {
  if constexpr (!detail::NamesLayerScalar<L>)
    static_assert(detail::layer_check_failed<L>,
                  "this type is not an nn::Layer: it lacks the member type scalar_type (nn/layer.hpp)");
  else if constexpr (!detail::ForwardsPolicyFirst<L>)
    static_assert(detail::layer_check_failed<L>,
                  "this type is not an nn::Layer: it lacks forward(policy, mode, in, out) with the execution policy first, "
                  "for exec::seq and exec::omp (nn/layer.hpp)");
  else if constexpr (!detail::BackwardsPolicyFirst<L>)
    static_assert(detail::layer_check_failed<L>,
                  "this type is not an nn::Layer: it lacks backward(policy, in, out, d_out, d_in*) with the execution policy "
                  "first, for exec::seq and exec::omp (nn/layer.hpp)");
  else if constexpr (!detail::ReportsOutFeatures<L>)
    static_assert(detail::layer_check_failed<L>,
                  "this type is not an nn::Layer: it lacks out_features(in_cols) const (nn/layer.hpp)");
  return true;
}

}  // namespace simsr::nn
