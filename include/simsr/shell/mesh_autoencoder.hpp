#pragma once
/// \file
/// The convolutional mesh encoders of Chen et al. 2023 (supplement §3): TS-ACAP features of one
/// frame (V×9) → a 16-d latent, by two mesh convolutions (Eq. 5), each followed by layer
/// normalization, tanh after the first and no activation after the last, then one fully
/// connected layer; and the mirror decoder, latent → features, that brings a synthesized fine
/// latent back to fine TS-ACAP features (the supplement does not print it: this is the encoder
/// reversed, as in Tan et al. 2022's mesh autoencoders).
///
///     shell::MeshEncoder<float> enc(store, "coarse_enc", adjacency, {.channels = 9, .latent = 16}, rng);
///     enc.forward(exec::omp, nn::Mode::train, features, z);    // (B·V)×9 → B×16
///     shell::MeshDecoder<float> dec(store, "fine_dec", adjacency, {.channels = 9, .latent = 16}, rng);
///     dec.forward(exec::omp, nn::Mode::train, z, features);    // B×16 → (B·V)×9

#include <string>

#include "../mesh/topology.hpp"
#include "../nn/activations.hpp"
#include "../nn/layer_norm.hpp"
#include "../nn/linear.hpp"
#include "../nn/mesh_conv.hpp"
#include "ts_acap.hpp"

namespace simsr::shell {

struct MeshCodecOptions {
  Index channels = 9;  ///< channels of the hidden convolutions (the feature size, as Tan et al. 2022)
  Index latent = 16;   ///< the supplement's latent size (its Fig. 3: larger overfits)
};

namespace detail {
/// (B·V)×C rows ↔ B×(V·C) rows: the same numbers in row-major order.
template <class S>
void to_batch_rows(const nn::ConstView<S>& in, Index B, nn::Matrix<S>& out) {
  nn::ensure_shape(out, B, in.size() / B);
  for (Index r = 0; r < in.rows(); ++r)
    for (Index c = 0; c < in.cols(); ++c) out.data()[r * in.cols() + c] = in(r, c);
}
template <class S>
void to_vertex_rows(const nn::ConstView<S>& in, Index V, nn::Matrix<S>& out) {
  const Index C = in.cols() / V;
  nn::ensure_shape(out, in.rows() * V, C);
  for (Index b = 0; b < in.rows(); ++b)
    for (Index k = 0; k < in.cols(); ++k) out.data()[b * in.cols() + k] = in(b, k);
}
}  // namespace detail

/// Features (B·V)×9 → latents B×latent (an nn::Layer).
template <class S = float>
class MeshEncoder {
 public:
  using scalar_type = S;
  MeshEncoder(nn::ParameterStore<S>& store, const std::string& name, const Adjacency& graph, MeshCodecOptions options, nn::Rng& rng)
      : v_(graph.num_vertices()), opt_(options),
        conv1_(store, name + ".conv1", graph, ts_acap_feature_dim, options.channels, rng),
        norm1_(store, name + ".norm1", options.channels),
        conv2_(store, name + ".conv2", graph, options.channels, options.channels, rng),
        norm2_(store, name + ".norm2", options.channels),
        fc_(store, name + ".fc", graph.num_vertices() * options.channels, options.latent, rng) {}

  Index out_features(Index = -1) const { return opt_.latent; }
  Index num_vertices() const { return v_; }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, nn::Mode mode, const nn::ConstView<S>& in, nn::Matrix<S>& out) {
    conv1_.forward(policy, mode, in, h1_);
    norm1_.forward(policy, mode, h1_, n1_);
    act_.forward(policy, mode, n1_, a1_);
    conv2_.forward(policy, mode, a1_, h2_);
    norm2_.forward(policy, mode, h2_, n2_);
    detail::to_batch_rows<S>(n2_, in.rows() / v_, flat_);
    fc_.forward(policy, mode, flat_, out);
  }
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const nn::ConstView<S>& in, const nn::ConstView<S>& out, const nn::ConstView<S>& d_out, nn::Matrix<S>* d_in) {
    fc_.backward(policy, flat_, out, d_out, &d_flat_);
    detail::to_vertex_rows<S>(d_flat_, v_, d_n2_);
    norm2_.backward(policy, h2_, n2_, d_n2_, &d_h2_);
    conv2_.backward(policy, a1_, h2_, d_h2_, &d_a1_);
    act_.backward(policy, n1_, a1_, d_a1_, &d_n1_);
    norm1_.backward(policy, h1_, n1_, d_n1_, &d_h1_);
    conv1_.backward(policy, in, h1_, d_h1_, d_in);
  }

 private:
  Index v_;
  MeshCodecOptions opt_;
  nn::MeshConv<S> conv1_;
  nn::LayerNorm<S> norm1_;
  nn::Tanh<S> act_;
  nn::MeshConv<S> conv2_;
  nn::LayerNorm<S> norm2_;
  nn::Linear<S> fc_;
  nn::Matrix<S> h1_, n1_, a1_, h2_, n2_, flat_, d_flat_, d_n2_, d_h2_, d_a1_, d_n1_, d_h1_;
};
static_assert(nn::assert_layer<MeshEncoder<float>>());

/// Latents B×latent → features (B·V)×9: a fully connected layer to V×channels, layer
/// normalization and tanh, a mesh convolution with normalization and tanh, and a last mesh
/// convolution to the 9 features with no activation (an nn::Layer).
template <class S = float>
class MeshDecoder {
 public:
  using scalar_type = S;
  MeshDecoder(nn::ParameterStore<S>& store, const std::string& name, const Adjacency& graph, MeshCodecOptions options, nn::Rng& rng)
      : v_(graph.num_vertices()), opt_(options),
        fc_(store, name + ".fc", options.latent, graph.num_vertices() * options.channels, rng),
        norm0_(store, name + ".norm0", options.channels),
        conv1_(store, name + ".conv1", graph, options.channels, options.channels, rng),
        norm1_(store, name + ".norm1", options.channels),
        conv2_(store, name + ".conv2", graph, options.channels, ts_acap_feature_dim, rng) {}

  Index out_features(Index = -1) const { return ts_acap_feature_dim; }
  Index num_vertices() const { return v_; }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, nn::Mode mode, const nn::ConstView<S>& in, nn::Matrix<S>& out) {
    fc_.forward(policy, mode, in, flat_);
    detail::to_vertex_rows<S>(flat_, v_, h0_);
    norm0_.forward(policy, mode, h0_, n0_);
    act0_.forward(policy, mode, n0_, a0_);
    conv1_.forward(policy, mode, a0_, h1_);
    norm1_.forward(policy, mode, h1_, n1_);
    act1_.forward(policy, mode, n1_, a1_);
    conv2_.forward(policy, mode, a1_, out);
  }
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const nn::ConstView<S>& in, const nn::ConstView<S>& out, const nn::ConstView<S>& d_out, nn::Matrix<S>* d_in) {
    conv2_.backward(policy, a1_, out, d_out, &d_a1_);
    act1_.backward(policy, n1_, a1_, d_a1_, &d_n1_);
    norm1_.backward(policy, h1_, n1_, d_n1_, &d_h1_);
    conv1_.backward(policy, a0_, h1_, d_h1_, &d_a0_);
    act0_.backward(policy, n0_, a0_, d_a0_, &d_n0_);
    norm0_.backward(policy, h0_, n0_, d_n0_, &d_h0_);
    detail::to_batch_rows<S>(d_h0_, in.rows(), d_flat_);
    fc_.backward(policy, in, flat_, d_flat_, d_in);
  }

 private:
  Index v_;
  MeshCodecOptions opt_;
  nn::Linear<S> fc_;
  nn::LayerNorm<S> norm0_;
  nn::Tanh<S> act0_;
  nn::MeshConv<S> conv1_;
  nn::LayerNorm<S> norm1_;
  nn::Tanh<S> act1_;
  nn::MeshConv<S> conv2_;
  nn::Matrix<S> flat_, h0_, n0_, a0_, h1_, n1_, a1_, d_a1_, d_n1_, d_h1_, d_a0_, d_n0_, d_h0_, d_flat_;
};
static_assert(nn::assert_layer<MeshDecoder<float>>());

}  // namespace simsr::shell
