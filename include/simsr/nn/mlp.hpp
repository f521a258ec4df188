#pragma once
/// \file
/// A stack of per-point (1×1 convolution) stages, each Linear → optional BatchNorm → activation:
/// the shape of every MLP of the network (SPEC §7): the EdgeConv edge MLP, `fc_out` of each
/// embedding block, the upsampling weight network, the SIREN decoder.
///
///     std::vector<nn::MlpStage> st = {
///       nn::MlpStage::linear(7, 128, "conv_weights.0").no_bias().norm("conv_weights.1").then(nn::Act::sine),
///       nn::MlpStage::linear(128, 1, "conv_weights.3")};
///     nn::Mlp<float> mlp(store, "net_upscale", st, rng);
///     mlp.forward(exec::omp, nn::Mode::train, q, logits);
///
/// Names are the caller's (PyTorch nn.Sequential indices differ by profile), prefixed by `prefix.`.

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "activations.hpp"
#include "batch_norm.hpp"
#include "linear.hpp"

namespace simsr::nn {

/// Activation after a stage: none (identity), LeakyReLU(slope), sin(ω₀·x).
enum class Act { none, leaky_relu, sine };

/// Initialization of a stage's Linear: PyTorch's default U(±1/√in), or SIREN's (first layer
/// U(±1/in), later U(±√(6/in)/ω₀); see siren_init).
enum class Init { pytorch_default, siren_first, siren };

/// One stage. `omega0` is the sine's ω₀ and the ω₀ of a SIREN init; `slope` LeakyReLU's.
struct MlpStage {
  Index in = 0, out = 0;
  bool bias = true;
  bool batch_norm = false;
  Act act = Act::none;
  double omega0 = 1.0;
  double slope = 0.2;
  Init init = Init::pytorch_default;
  int kernel_dims = 1;  ///< trailing 1s of the weight's state-dict shape (Conv1d 1, Conv2d 2, Linear 0)
  std::string linear_name, bn_name;
  typename BatchNorm1d<float>::Options bn{};

  /// A Linear in→out named `name` (with bias, Conv1d-shaped weight, no activation).
  static MlpStage linear(Index in, Index out, std::string name) {
    MlpStage s;
    s.in = in;
    s.out = out;
    s.linear_name = std::move(name);
    return s;
  }
  MlpStage& no_bias() { return bias = false, *this; }
  MlpStage& dims(int trailing_ones) { return kernel_dims = trailing_ones, *this; }
  /// BatchNorm after the Linear, named `name`.
  MlpStage& norm(std::string name, typename BatchNorm1d<float>::Options options = {}) {
    batch_norm = true;
    bn_name = std::move(name);
    bn = options;
    return *this;
  }
  /// Activation after the stage: LeakyReLU(param) or sin(param·x).
  MlpStage& then(Act a, double param) {
    act = a;
    (a == Act::sine ? omega0 : slope) = param;
    return *this;
  }
  /// SIREN initialization of the Linear (first layer or later) for sin(ω₀·).
  MlpStage& siren(bool first, double w0) {
    init = first ? Init::siren_first : Init::siren;
    omega0 = w0;
    return *this;
  }
};

/// The stages in order; forward keeps every intermediate for backward. Not copyable (layers
/// point into the store); one object serves one place in the graph.
/// The tensors an Mlp of `stages` registers under `prefix`, in its order, without building it
/// (shapes only, offsets 0): what a model file must hold for it (nn::network_state_shapes).
inline void append_state_shapes(std::vector<TensorEntry>& out, const std::string& prefix, const std::vector<MlpStage>& stages) {
  const std::string p = prefix.empty() ? "" : prefix + ".";
  auto add = [&](std::string name, std::vector<Index> shape, TensorEntry::Kind kind) {
    Index size = 1;
    for (Index d : shape) size *= d;
    out.push_back(TensorEntry{std::move(name), std::move(shape), kind, 0, size});
  };
  for (const MlpStage& s : stages) {
    std::vector<Index> w{s.out, s.in};
    w.insert(w.end(), static_cast<std::size_t>(s.kernel_dims), Index(1));
    add(p + s.linear_name + ".weight", w, TensorEntry::Kind::parameter);
    if (s.bias) add(p + s.linear_name + ".bias", {s.out}, TensorEntry::Kind::parameter);
    if (!s.batch_norm) continue;
    if (s.bn.affine) {
      add(p + s.bn_name + ".weight", {s.out}, TensorEntry::Kind::parameter);
      add(p + s.bn_name + ".bias", {s.out}, TensorEntry::Kind::parameter);
    }
    if (s.bn.track_running_stats) {
      add(p + s.bn_name + ".running_mean", {s.out}, TensorEntry::Kind::buffer);
      add(p + s.bn_name + ".running_var", {s.out}, TensorEntry::Kind::buffer);
      add(p + s.bn_name + ".num_batches_tracked", {}, TensorEntry::Kind::buffer);
    }
  }
}

template <class S = float>
class Mlp {
 public:
  using scalar_type = S;

  Mlp(ParameterStore<S>& store, const std::string& prefix, const std::vector<MlpStage>& stages, Rng& rng) {
    if (stages.empty()) throw ArgumentError("nn::Mlp '" + prefix + "': needs at least one stage");
    const std::string p = prefix.empty() ? "" : prefix + ".";
    for (std::size_t i = 0; i < stages.size(); ++i) {
      const MlpStage& s = stages[i];
      if (i > 0 && s.in != stages[i - 1].out)
        throw ArgumentError("nn::Mlp '" + prefix + "': stage " + std::to_string(i) + " takes " + std::to_string(s.in) +
                            " features but the previous stage gives " + std::to_string(stages[i - 1].out));
      if (s.linear_name.empty()) throw ArgumentError("nn::Mlp '" + prefix + "': stage " + std::to_string(i) + " needs a linear_name");
      auto st = std::make_unique<Stage>();
      st->spec = s;
      st->linear.emplace(store, p + s.linear_name, s.in, s.out, rng, typename Linear<S>::Options{.bias = s.bias, .kernel_dims = s.kernel_dims});
      if (s.init != Init::pytorch_default) siren_init(*st->linear, rng, s.omega0, s.init == Init::siren_first);
      if (s.batch_norm) {
        if (s.bn_name.empty()) throw ArgumentError("nn::Mlp '" + prefix + "': stage " + std::to_string(i) + " needs a bn_name");
        st->bn.emplace(store, p + s.bn_name, s.out,
                       typename BatchNorm1d<S>::Options{.eps = s.bn.eps, .momentum = s.bn.momentum, .affine = s.bn.affine,
                                                        .track_running_stats = s.bn.track_running_stats});
      }
      st->leaky.emplace(static_cast<S>(s.slope));
      st->sine.emplace(static_cast<S>(s.omega0));
      stages_.push_back(std::move(st));
    }
  }

  Index stages() const { return Index(stages_.size()); }
  Index in_features() const { return stages_.front()->spec.in; }
  Index out_features(Index = -1) const { return stages_.back()->spec.out; }
  Linear<S>& linear(Index i) { return *stage(i).linear; }
  /// The BatchNorm of stage i; ArgumentError when the stage has none.
  BatchNorm1d<S>& batch_norm(Index i) {
    if (!stage(i).bn) throw ArgumentError("nn::Mlp: stage " + std::to_string(i) + " has no BatchNorm");
    return *stage(i).bn;
  }
  const MlpStage& spec(Index i) const { return stages_.at(std::size_t(i))->spec; }

  /// The batch split of data-parallel training for every Linear and BatchNorm of the stack
  /// (nullptr: none). Only for an Mlp whose rows are batch rows.
  void set_batch_split(BatchSplit* split) {
    for (auto& s : stages_) {
      s->linear->set_batch_split(split);
      if (s->bn) s->bn->set_batch_split(split);
    }
  }

  /// Eval mode (every BatchNorm on running statistics): all stages run on one row chunk after the
  /// other (the chunks of Linear::forward), BatchNorm and the activation applied in place on the
  /// chunk (same arithmetic, same values); only the output is stored, and a backward after it
  /// recomputes the stored forward first.
  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& in, Matrix<S>& out) {
    if (mode == Mode::eval && eval_fusable()) {
      forward_fused(policy, in, out);
      lean_ = true;
      return;
    }
    lean_ = false;
    forward_stored(policy, mode, in, out);
  }

  /// After forward(policy, …, in, out): parameter gradients added, d_in written when not null.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>& out, const ConstView<S>& d_out, Matrix<S>* d_in) {
    if (lean_) {  // the fused eval forward kept only the stage outputs: redo it storing everything
      forward_stored(policy, Mode::eval, in, recomputed_);
      lean_ = false;
    }
    backward_stored(policy, in, out, d_out, d_in);
  }

  /// True when the eval forward can be fused: every BatchNorm uses running statistics in eval.
  bool eval_fusable() const {
    for (const auto& s : stages_)
      if (s->bn && !s->bn->eval_uses_running_stats()) return false;
    return true;
  }
  /// The fused eval forward in pieces, for a caller that makes its input chunk by chunk (EdgeConv
  /// gathers its edge rows): prepare_eval_blocks(R, workers) once per forward of R rows, then
  /// eval_block(worker, …) on each row chunk of Linear::forward's chunking of R rows (row-major
  /// blocks, leading dimensions ld_in, ld_out). The values are those of forward(Mode::eval). A
  /// later backward recomputes the stored forward first.
  void prepare_eval_blocks(Index R, Index workers) {
    if (!eval_fusable()) throw ArgumentError("nn::Mlp: the fused eval path needs BatchNorm with running statistics");
    for (auto& s : stages_)
      if (s->bn) s->bn->prepare_eval();
    Index width = 0;
    for (const auto& s : stages_) width = std::max(width, s->spec.out);
    const Index rows = exec::max_chunk_size(R, exec::chunk_count(R, product_chunks));
    for (auto& s : stages_) s->linear->prepare_forward();  // the current weights, packed once for every chunk
    if (scratch_.size() < std::size_t(workers)) scratch_.resize(std::size_t(workers));
    for (Index w = 0; w < workers; ++w) {
      Scratch& sc = scratch_[std::size_t(w)];
      for (auto& m : sc.buf) ensure_shape(m, rows, width);
      for (auto& s : stages_) s->linear->reserve_forward(sc.ws);
    }
    lean_ = true;
  }
  void eval_block(Index w, Index rows, const S* in, Index ld_in, S* out, Index ld_out) { eval_stages(w, rows, in, ld_in, nullptr, 0, out, ld_out); }
  /// eval_block for a caller that computed stage 0's Linear itself (bias included) into `y0`
  /// (rows × spec(0).out, leading dimension ld0): stage 0's BatchNorm and activation are applied
  /// to it in place, then the later stages run as in eval_block. EdgeConv's point-wise first
  /// layer and forward_eval_parts use it.
  void eval_block_after_first_linear(Index w, Index rows, S* y0, Index ld0, S* out, Index ld_out) {
    eval_stages(w, rows, nullptr, 0, y0, ld0, out, ld_out);
  }

  /// One input part of forward_eval_parts: `per_item` parts hold one row per batch item (B rows),
  /// the others one row per row of the output (B·rows_per_item rows).
  struct InputPart {
    ConstView<S> values;
    bool per_item = false;
  };

  /// Eval forward (BatchNorm on running statistics) of cat(parts) without forming it: stage 0's
  /// Linear is applied part by part, and the parts that are the same on every row of a batch
  /// item (an embedding block's global max and mean) once per item instead of once per row:
  /// W·cat(x, g) = W_x·x + (W_g·g + b). The values are forward(Mode::eval)'s on the concatenation
  /// up to rounding (the products are summed in another order), seq == omp bitwise. Allocates
  /// nothing once warm; a backward after it needs the concatenation (as after forward: pass it).
  template <exec::HostPolicy Policy>
  void forward_eval_parts(Policy policy, std::initializer_list<InputPart> parts, Index rows_per_item, Matrix<S>& out) {
    forward_eval_parts(policy, std::span<const InputPart>(parts.begin(), parts.size()), rows_per_item, out);
  }
  /// The same with the parts in a span (a number of parts known at run time).
  template <exec::HostPolicy Policy>
  void forward_eval_parts(Policy policy, std::span<const InputPart> parts, Index rows_per_item, Matrix<S>& out) {
    if (!eval_fusable()) throw ArgumentError("nn::Mlp::forward_eval_parts: needs BatchNorm with running statistics (eval mode)");
    if (parts.size() == 0 || rows_per_item < 1) throw ArgumentError("nn::Mlp::forward_eval_parts: needs parts and rows_per_item >= 1");
    Index R = -1, width = 0;
    for (const InputPart& p : parts) {
      width += p.values.cols();
      if (!p.per_item) R = p.values.rows();
    }
    const auto where = [&] { return "nn::Mlp::forward_eval_parts ('" + stages_[0]->linear->name() + "')"; };  // built only to throw
    if (R < 0) throw ArgumentError(where() + ": every part is per item; at least one must have a row per output row");
    if (width != in_features())
      throw ShapeError(where() + ": the parts' columns must add up to the input width", {R, in_features()}, {R, width});
    if (R % rows_per_item)
      throw ShapeError(where() + ": rows (a multiple of rows_per_item = " + std::to_string(rows_per_item) + ")", {-1, width}, {R, width});
    const Index B = R / rows_per_item;
    Index part = 0;
    for (const InputPart& p : parts) {
      if (p.values.rows() != (p.per_item ? B : R))
        throw ShapeError(where() + ": part " + std::to_string(part) + (p.per_item ? " (one row per item)" : " (one row per row)"),
                         {p.per_item ? B : R, p.values.cols()}, {p.values.rows(), p.values.cols()});
      ++part;
    }

    Stage& s0 = *stages_[0];
    const Index H = s0.spec.out, in = in_features();
    const S* W = s0.linear->weight().data();  // H × in, row-major: the columns of part p start at W + offset
    // the per-item terms, with the bias: item_terms_ (B × H)
    ensure_shape(item_terms_, B, H);
    if (s0.linear->has_bias())
      item_terms_.rowwise() = s0.linear->bias().transpose();
    else
      item_terms_.setZero();
    // the per-row parts' columns of W, each packed once for every chunk
    if (part_packed_.size() < parts.size()) part_packed_.resize(parts.size());
    Index offset = 0;
    for (std::size_t i = 0; i < parts.size(); ++i) {
      const InputPart& p = parts[i];
      if (p.per_item)
        item_gemm_.run(B, H, p.values.cols(), p.values.data(), p.values.outerStride(), false, W + offset, in, true, item_terms_.data(), H, true);
      else
        part_packed_[i].pack(W + offset, H, p.values.cols(), in);
      offset += p.values.cols();
    }
    for_eval_chunks(policy, R, out, [&](Index w, Index b, Index e) {
      Scratch& sc = scratch_[std::size_t(w)];
      Matrix<S>& first = sc.buf[0];  // stage 0's output, as eval_block keeps it
      S* y0 = first.data();
      const Index ld0 = first.cols();
      for (Index r = b; r < e; ++r) std::copy_n(item_terms_.row(r / rows_per_item).data(), H, y0 + (r - b) * ld0);  // the sums start there
      for (std::size_t i = 0; i < parts.size(); ++i) {
        const InputPart& p = parts[i];
        if (!p.per_item)
          part_packed_[i].run(sc.ws, e - b, p.values.data() + b * p.values.outerStride(), p.values.outerStride(), nullptr, y0, ld0, true);
      }
      eval_block_after_first_linear(w, e - b, y0, ld0, out.data() + b * out.cols(), out.cols());
    });
  }

  /// Stage 0's Linear without its bias: out = in·W₀ᵀ (rows × spec(0).out). With
  /// forward_eval_from_products it splits the eval forward where a linear map of the rows can sit
  /// between the two (SuperResolutionNet's inference moves the decoder's first layer before the
  /// upsampling: W₀·Σ_i w_i z_i = Σ_i w_i·W₀z_i): Linear::forward_without_bias.
  template <exec::HostPolicy Policy>
  void first_linear_products(Policy policy, const ConstView<S>& in, Matrix<S>& out) {
    stages_[0]->linear->forward_without_bias(policy, in, out);
  }

  /// Eval forward (BatchNorm on running statistics) of R rows whose stage-0 products (in·W₀ᵀ, no
  /// bias) the caller writes chunk by chunk: `products(begin, end, y, ld)` fills rows [begin, end)
  /// into y (leading dimension ld); the bias, BatchNorm, activation and the later stages follow
  /// as in forward(Mode::eval), on the chunk while it is in cache. Allocates nothing once warm; a
  /// backward after it needs the input (as after forward: pass it).
  template <exec::HostPolicy Policy, class Products>
  void forward_eval_from_products(Policy policy, Index R, Products&& products, Matrix<S>& out) {
    if (!eval_fusable()) throw ArgumentError("nn::Mlp::forward_eval_from_products: needs BatchNorm with running statistics (eval mode)");
    if (R < 0) throw ArgumentError("nn::Mlp::forward_eval_from_products: negative row count " + std::to_string(R));
    Stage& s0 = *stages_[0];
    const Index H = s0.spec.out;
    for_eval_chunks(policy, R, out, [&](Index w, Index b, Index e) {
      Matrix<S>& first = scratch_[std::size_t(w)].buf[0];  // stage 0's output, as eval_block keeps it
      S* y0 = first.data();
      const Index ld0 = first.cols();
      products(b, e, y0, ld0);
      if (s0.linear->has_bias()) {
        Eigen::Map<Matrix<S>, 0, Eigen::OuterStride<>> y(y0, e - b, H, Eigen::OuterStride<>(ld0));
        y.rowwise() += s0.linear->bias().transpose();
      }
      eval_block_after_first_linear(w, e - b, y0, ld0, out.data() + b * out.cols(), out.cols());
    });
  }

 private:
  template <class Policy>
  void forward_stored(Policy policy, Mode mode, const ConstView<S>& in, Matrix<S>& out) {
    const ConstView<S>* x = &in;
    std::optional<ConstView<S>> view;
    const std::size_t last = stages_.size() - 1;
    for (std::size_t i = 0; i <= last; ++i) {
      Stage& s = *stages_[i];
      // The last stage writes its final activation straight into `out`.
      Matrix<S>& lin_out = (i == last && !s.bn && s.spec.act == Act::none) ? out : s.lin;
      s.linear->forward(policy, mode, *x, lin_out);
      const Matrix<S>* y = &lin_out;
      if (s.bn) {
        Matrix<S>& bn_out = (i == last && s.spec.act == Act::none) ? out : s.normed;
        s.bn->forward(policy, mode, *y, bn_out);
        y = &bn_out;
      }
      if (s.spec.act != Act::none) {
        Matrix<S>& act_out = i == last ? out : s.activated;
        activation_forward(policy, s, mode, *y, act_out);
        y = &act_out;
      }
      view.emplace(*y);
      x = &*view;
    }
  }

  /// All stages over each fixed row chunk (the chunks of Linear::forward), with per-worker
  /// scratch: the chunk stays in cache from the first Linear to the last activation.
  template <class Policy>
  void forward_fused(Policy policy, const ConstView<S>& in, Matrix<S>& out) {
    const Index R = in.rows();
    if (in.cols() != in_features()) detail::check_shape("nn::Linear '" + stages_[0]->linear->name() + "'", "input", in, -1, in_features());
    for_eval_chunks(policy, R, out, [&](Index w, Index b, Index e) {
      eval_block(w, e - b, in.data() + b * in.outerStride(), in.outerStride(), out.data() + b * out.cols(), out.cols());
    });
  }

  /// The fused eval paths' loop: out sized R × out_features(), the scratch prepared, body(worker,
  /// begin, end) on each row chunk of Linear::forward's chunking.
  template <class Policy, class Body>
  void for_eval_chunks(Policy policy, Index R, Matrix<S>& out, Body&& body) {
    ensure_shape(out, R, out_features());
    const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
    prepare_eval_blocks(R, workers);
    detail::for_chunks_dynamic(policy, R, nc, workers, [&](Index w, Index, Index b, Index e) { body(w, b, e); });
  }

  template <class Policy>
  void backward_stored(Policy policy, const ConstView<S>& in, const ConstView<S>& out, const ConstView<S>& d_out, Matrix<S>* d_in) {
    const std::size_t last = stages_.size() - 1;
    const ConstView<S>* g = &d_out;
    std::optional<ConstView<S>> gview;
    for (std::size_t ii = stages_.size(); ii-- > 0;) {
      Stage& s = *stages_[ii];
      const bool is_last = ii == last;
      // the stage's tensors: lin (Linear output), normed (BN output), the activation output
      const ConstView<S> lin_out = (is_last && !s.bn && s.spec.act == Act::none) ? ConstView<S>(out) : ConstView<S>(s.lin);
      const ConstView<S> bn_out = !s.bn ? lin_out : (is_last && s.spec.act == Act::none) ? ConstView<S>(out) : ConstView<S>(s.normed);
      if (s.spec.act != Act::none) {
        const ConstView<S> act_out = is_last ? ConstView<S>(out) : ConstView<S>(s.activated);
        activation_backward(policy, s, bn_out, act_out, *g, s.g_act);
        gview.emplace(s.g_act);
        g = &*gview;
      }
      if (s.bn) {
        s.bn->backward(policy, lin_out, bn_out, *g, &s.g_bn);
        gview.emplace(s.g_bn);
        g = &*gview;
      }
      const ConstView<S> x = ii == 0 ? in : stage_output(ii - 1);
      Matrix<S>* dx = ii == 0 ? d_in : &s.g_in;
      s.linear->backward(policy, x, lin_out, *g, dx);
      if (ii > 0) {
        gview.emplace(s.g_in);
        g = &*gview;
      }
    }
  }

  struct Stage {
    MlpStage spec;
    std::optional<Linear<S>> linear;
    std::optional<BatchNorm1d<S>> bn;
    std::optional<LeakyReLU<S>> leaky;
    std::optional<Sine<S>> sine;
    Matrix<S> lin, normed, activated, g_act, g_bn, g_in;
  };

  Stage& stage(Index i) {
    if (i < 0 || i >= stages()) throw ArgumentError("nn::Mlp: no stage " + std::to_string(i));
    return *stages_[std::size_t(i)];
  }
  /// Output of a stage that is not the last one.
  ConstView<S> stage_output(std::size_t i) const {
    const Stage& s = *stages_[i];
    if (s.spec.act != Act::none) return s.activated;
    if (s.bn) return s.normed;
    return s.lin;
  }
  template <class Policy>
  void activation_forward(Policy policy, Stage& s, Mode mode, const ConstView<S>& x, Matrix<S>& y) {
    if (s.spec.act == Act::leaky_relu)
      s.leaky->forward(policy, mode, x, y);
    else
      s.sine->forward(policy, mode, x, y);
  }
  template <class Policy>
  void activation_backward(Policy policy, Stage& s, const ConstView<S>& x, const ConstView<S>& y, const ConstView<S>& g, Matrix<S>& dx) {
    if (s.spec.act == Act::leaky_relu)
      s.leaky->backward(policy, x, y, g, &dx);
    else
      s.sine->backward(policy, x, y, g, &dx);
  }

  /// Per worker of the fused eval path: ping-pong stage outputs of one chunk, the products' scratch.
  struct Scratch {
    Matrix<S> buf[2];
    typename Linear<S>::Workspace ws;  ///< every stage's products (one stage after the other)
  };

  /// eval_block's body. With `y0` set, stage 0's Linear output is there already (leading
  /// dimension ld0) and is post-processed in place; otherwise stage 0 reads `in`.
  void eval_stages(Index w, Index rows, const S* in, Index ld_in, S* y0, Index ld0, S* out, Index ld_out) {
    Scratch& sc = scratch_[std::size_t(w)];
    const S* x = in;
    Index ldx = ld_in;
    const std::size_t last = stages_.size() - 1;
    for (std::size_t i = 0; i <= last; ++i) {
      Stage& s = *stages_[i];
      S* y = i == last ? out : sc.buf[i % 2].data();
      Index ldy = i == last ? ld_out : sc.buf[i % 2].cols();
      if (i == 0 && y0) {
        y = y0, ldy = ld0;
      } else {
        s.linear->forward_block(sc.ws, rows, x, ldx, y, ldy);
      }
      if (s.bn) s.bn->apply_eval(y, ldy, rows);
      apply_activation(s, y, ldy, rows);
      if (i == last && y != out)
        for (Index r = 0; r < rows; ++r) std::copy_n(y + r * ldy, s.spec.out, out + r * ld_out);
      x = y;
      ldx = ldy;
    }
  }
  /// The stage's activation on a rows × out block in place (as LeakyReLU / Sine: the same bits).
  static void apply_activation(const Stage& s, S* y, Index ldy, Index rows) {
    const Index C = s.spec.out;
    if (s.spec.act == Act::leaky_relu) {
      const S slope = static_cast<S>(s.spec.slope);
      for (Index r = 0; r < rows; ++r) {
        S* p = y + r * ldy;
        for (Index c = 0; c < C; ++c) p[c] = p[c] > S(0) ? p[c] : slope * p[c];
      }
    } else if (s.spec.act == Act::sine) {
      const S w0 = static_cast<S>(s.spec.omega0);  // Eigen's packet sin, as nn::Sine: the same bits
      const auto sine = [w0](const auto& v) { return (v * w0).sin(); };
      if (ldy == C) {
        detail::map_packets(y, rows * C, sine, static_cast<const S*>(y));
      } else {
        for (Index r = 0; r < rows; ++r) detail::map_packets(y + r * ldy, C, sine, static_cast<const S*>(y + r * ldy));
      }
    }
  }

  std::vector<std::unique_ptr<Stage>> stages_;
  std::vector<Scratch> scratch_;
  bool lean_ = false;     ///< the last forward was the fused eval one: only its output is stored
  Matrix<S> recomputed_;  ///< output of the storing forward that an eval backward redoes
  Matrix<S> item_terms_;  ///< forward_eval_parts: the per-item parts' products and the bias (B × out of stage 0)
  SerialGemm<S> item_gemm_;
  std::vector<PackedGemm<S>> part_packed_;  ///< forward_eval_parts: the per-row parts' columns of stage 0's weight
};
static_assert(assert_layer<Mlp<float>>());

}  // namespace simsr::nn
