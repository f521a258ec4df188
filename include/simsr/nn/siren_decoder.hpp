#pragma once
/// \file
/// The surface reconstruction network of §3.3 (SPEC §7 `decoder`): a SIREN over the upsampled
/// code, dims[0] → … → dims[-2] with sin(ω₀·) (ω₀ = w0_initial on the first layer, w0 after),
/// then a linear dims[-2] → 3 (`last_layer`). The official SirenNet also builds a sixth sine layer
/// dims[-2] → dims[-1] that its forward never calls (zip over five ω₀ values): with
/// `decoder_dead_layer` it is registered (and initialized) in its state-dict place so official
/// weights load; it gets no gradient.
///
/// Names: `<prefix>.layers.<i>.fc.{weight,bias}` (nn.Linear), `<prefix>.last_layer.fc.*`.
/// The decoder is an nn::Sequential of two Mlps (the sine layers, then last_layer).

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "mlp.hpp"
#include "network_config.hpp"
#include "sequential.hpp"

namespace simsr::nn {

template <class S = float>
class SirenDecoder {
 public:
  using scalar_type = S;

  SirenDecoder(ParameterStore<S>& store, const std::string& prefix, const NetworkConfig& cfg, Rng& rng)
      : net_(build(store, prefix, cfg, rng, dead_)) {}

  Index in_features() const { return net_.template layer<0>().in_features(); }
  /// Sets `last_layer` to zero, so the decoder starts by predicting 0 (the residual option starts
  /// exactly at the interpolator it corrects; the hidden layers get gradients from the 2nd step).
  void zero_output_layer() {
    net_.template layer<1>().linear(0).weight().setZero();
    net_.template layer<1>().linear(0).bias().setZero();
  }
  Index out_features(Index = -1) const { return net_.template layer<1>().out_features(); }
  /// The batch split of data-parallel training (its rows are the batch's HR vertices).
  void set_batch_split(BatchSplit* split) {
    net_.template layer<0>().set_batch_split(split);
    net_.template layer<1>().set_batch_split(split);
  }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& zH, Matrix<S>& out) {
    net_.forward(policy, mode, zH, out);
  }

  /// The sine layers and the linear output layer (`last_layer`), in forward order.
  Mlp<S>& sine_layers() { return net_.template layer<0>(); }
  Mlp<S>& output_layer() { return net_.template layer<1>(); }
  /// Width of the first sine layer (its Linear's outputs).
  Index first_layer_width() const { return net_.template layer<0>().spec(0).out; }

  /// The eval forward split after the first Linear's products, for a caller with a linear map of
  /// the rows in between (SuperResolutionNet's inference: W₁·Σ_i w_ji z_i = Σ_i w_ji·W₁z_i, so the
  /// products are taken on the N LR rows and gathered, instead of on the M upsampled ones).
  /// first_layer_products: y = z·W₁ᵀ, no bias. forward_eval_from_products: `products(begin, end,
  /// y, ld)` writes rows [begin, end) of the (gathered) products; the bias, the sine, the later
  /// layers and last_layer follow as in forward(Mode::eval). Not for training: no backward after it.
  template <exec::HostPolicy Policy>
  void first_layer_products(Policy policy, const ConstView<S>& z, Matrix<S>& y) {
    net_.template layer<0>().first_linear_products(policy, z, y);
  }
  template <exec::HostPolicy Policy, class Products>
  void forward_eval_from_products(Policy policy, Index rows, Products&& products, Matrix<S>& out) {
    net_.template layer<0>().forward_eval_from_products(policy, rows, std::forward<Products>(products), hidden_);
    net_.template layer<1>().forward(policy, Mode::eval, hidden_, out);
  }

  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& zH, const ConstView<S>& out, const ConstView<S>& d_out, Matrix<S>* d_zH) {
    net_.backward(policy, zH, out, d_out, d_zH);
  }

 private:
  using Net = Sequential<Mlp<S>, Mlp<S>>;  ///< the sine layers, then last_layer

  /// Registers the sine layers, the dead layer (into `dead`, when the config has it) and
  /// last_layer, in the official state-dict order.
  static Net build(ParameterStore<S>& store, const std::string& prefix, const NetworkConfig& cfg, Rng& rng, std::unique_ptr<Mlp<S>>& dead) {
    const Stages st = stages(cfg);
    Mlp<S> sines(store, prefix, st.sines, rng);
    if (cfg.decoder_dead_layer) dead = std::make_unique<Mlp<S>>(store, prefix, st.dead, rng);
    Mlp<S> last(store, prefix, st.last, rng);
    return Net(std::move(sines), std::move(last));
  }

  struct Stages {
    std::vector<MlpStage> sines, dead, last;
  };
  static Stages stages(const NetworkConfig& cfg) {
    const auto& d = cfg.decoder_dims;
    if (d.size() < 3) throw ArgumentError("nn::SirenDecoder: decoder_dims needs at least one hidden width (in, hidden…, 3)");
    const std::size_t hidden = d.size() - 2;
    Stages st;
    for (std::size_t i = 0; i < hidden; ++i) {
      const double w0 = i == 0 ? cfg.w0_initial : cfg.w0;
      st.sines.push_back(MlpStage::linear(d[i], d[i + 1], "layers." + std::to_string(i) + ".fc").dims(0).siren(i == 0, w0).then(Act::sine, w0));
    }
    if (cfg.decoder_dead_layer)
      st.dead = {MlpStage::linear(d[hidden], d[hidden + 1], "layers." + std::to_string(hidden) + ".fc").dims(0).siren(false, cfg.w0)};
    st.last = {MlpStage::linear(d[hidden], d[hidden + 1], "last_layer.fc").dims(0).siren(false, cfg.w0)};
    return st;
  }

 public:
  /// The tensors this module registers under `prefix`, in its order (shapes only).
  static void append_state_shapes(std::vector<TensorEntry>& out, const std::string& prefix, const NetworkConfig& cfg) {
    const Stages st = stages(cfg);
    for (const auto* s : {&st.sines, &st.dead, &st.last}) nn::append_state_shapes(out, prefix, *s);
  }

 private:

  std::unique_ptr<Mlp<S>> dead_;  ///< registered only (official weights load), never run; before net_ (built first)
  Net net_;
  Matrix<S> hidden_;  ///< forward_eval_from_products: the sine layers' output, last_layer's input
};
static_assert(assert_layer<SirenDecoder<float>>());

}  // namespace simsr::nn
