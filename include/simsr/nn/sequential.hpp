#pragma once
/// \file
/// Layers run one after the other, each a template parameter checked by the nn::Layer concept:
/// swapping a layer is one type change, and the chain is itself a Layer (chains nest).
///
///     nn::Sequential<nn::Linear<float>, nn::LeakyReLU<float>, nn::Linear<float>> mlp{   // braces: built in order
///         nn::Linear<float>(store, "fc.0", 35, 64, rng), nn::LeakyReLU<float>(0.2f), nn::Linear<float>(store, "fc.2", 64, 3, rng)};
///     mlp.forward(exec::omp, nn::Mode::train, in, out);
///     mlp.backward(exec::omp, in, out, d_out, &d_in);
///
/// The SIREN decoder of the network is one (siren_decoder.hpp). A type that is not a Layer stops
/// the build with one sentence (nn::assert_layer).

#include <array>
#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>

#include "layer.hpp"

namespace simsr::nn {

namespace detail {
/// The first layer's scalar_type; float while it names none (assert_layer has already said so,
/// and the declarations below then compile without a cascade of further errors).
template <class L, class... Rest>
struct first_layer_scalar {
  using type = float;
};
template <class L, class... Rest>
  requires requires { typename L::scalar_type; }
struct first_layer_scalar<L, Rest...> {
  using type = typename L::scalar_type;
};
}  // namespace detail

/// out = L_n(… L_2(L_1(in))): forward keeps every intermediate activation for backward, which runs
/// the layers in reverse with the same policy. All layers share one scalar_type. Warm calls
/// allocate nothing beyond what the layers themselves do.
template <class... Ls>
class Sequential {
  static_assert(sizeof...(Ls) >= 1, "nn::Sequential needs at least one layer");
  static_assert((assert_layer<Ls>() && ...));

 public:
  using scalar_type = typename detail::first_layer_scalar<Ls...>::type;
  static constexpr std::size_t size = sizeof...(Ls);

  /// Takes the layers (moved in; layers that register parameters keep pointing into their store).
  /// Construct with braces when the layers register parameters or draw from one Rng: braced
  /// arguments are evaluated left to right, so registration order and draws are the layers' order.
  explicit Sequential(Ls... layers) : layers_(std::move(layers)...) {
    static_assert((std::is_same_v<typename detail::first_layer_scalar<Ls>::type, scalar_type> && ...), "nn::Sequential: all layers must share one scalar_type");
  }

  /// Layer I (0-based).
  template <std::size_t I>
  auto& layer() {
    return std::get<I>(layers_);
  }
  template <std::size_t I>
  const auto& layer() const {
    return std::get<I>(layers_);
  }
  /// The output of layer I < size − 1 in the last forward.
  const Matrix<scalar_type>& activation(std::size_t i) const { return acts_.at(i); }

  Index out_features(Index in_cols) const { return out_features_from<0>(in_cols); }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<scalar_type>& in, Matrix<scalar_type>& out) {
    forward_from<0>(policy, mode, in, out);
  }

  /// After forward(policy, mode, in, out): every layer's parameter gradients added, d_in written
  /// when not null.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<scalar_type>& in, const ConstView<scalar_type>& out, const ConstView<scalar_type>& d_out,
                Matrix<scalar_type>* d_in) {
    backward_from<size - 1>(policy, in, out, d_out, d_in);
  }

 private:
  using S = scalar_type;

  template <std::size_t I>
  Index out_features_from(Index cols) const {
    const Index c = std::get<I>(layers_).out_features(cols);
    if constexpr (I + 1 < size)
      return out_features_from<I + 1>(c);
    else
      return c;
  }
  template <std::size_t I, class Policy>
  void forward_from(Policy policy, Mode mode, const ConstView<S>& x, Matrix<S>& out) {
    if constexpr (I + 1 == size) {
      std::get<I>(layers_).forward(policy, mode, x, out);
    } else {
      std::get<I>(layers_).forward(policy, mode, x, acts_[I]);
      forward_from<I + 1>(policy, mode, acts_[I], out);
    }
  }
  /// Layer I reads acts_[I − 1] (in for I = 0), its output acts_[I] (out for the last) and the
  /// output gradient grads_[I] (d_out for the last), and writes grads_[I − 1] (d_in for I = 0).
  template <std::size_t I, class Policy>
  void backward_from(Policy policy, const ConstView<S>& in, const ConstView<S>& out, const ConstView<S>& d_out, Matrix<S>* d_in) {
    auto& layer = std::get<I>(layers_);
    auto run = [&](const ConstView<S>& y, const ConstView<S>& g) {
      if constexpr (I == 0)
        layer.backward(policy, in, y, g, d_in);
      else
        layer.backward(policy, acts_[I - 1], y, g, &grads_[I - 1]);
    };
    if constexpr (I + 1 == size)
      run(out, d_out);
    else
      run(acts_[I], grads_[I]);
    if constexpr (I > 0) backward_from<I - 1>(policy, in, out, d_out, d_in);
  }

  std::tuple<Ls...> layers_;
  std::array<Matrix<S>, size> acts_, grads_;  ///< the last entries stay unused (no zero-size array)
};

}  // namespace simsr::nn
