#pragma once
/// \file
/// The super-resolution network's inference as launches of device-callable bodies
/// (nn/detail/inference_kernels.hpp), over arrays in one memory space: `InferenceNet<S, HostBuffer>`
/// runs under exec::seq / exec::omp on host memory, `InferenceNet<S, DeviceBuffer>` (nvcc only)
/// the same launches under exec::cuda on a device. Issue #17 item 5: the network's inference
/// layers — positional encoding, the EdgeConv blocks with their feature kNN, global pools and
/// fc_out, the upsampling gather, the SIREN decoder, the residual base — as functor bodies that
/// run unchanged under seq, omp and cuda, with the buffers owned by the component.
///
///     net.prepare_inference(exec::omp);
///     nn::HostInferenceNet<float> host(exec::omp, net);           // the weights copied out once
///     host.infer(exec::omp, ldx, pred);                            // ConstView (B·N)×3 → (B·M)×3
///     auto dev = nn::to_device(exec::omp, net);                    // DeviceInferenceNet<float> (nvcc)
///     dev.infer(exec::cuda, ldx_span, pred_span);                  // MatrixSpans in device memory
///
/// Why a memory template here and not only a device twin: the host instance is the device code
/// path entire (every body, every launch, every buffer's size) run where tests run, so the CPU
/// tests check it against SuperResolutionNet::infer; only the launch differs on a device.
///
/// What it computes is SuperResolutionNet::infer's values up to rounding: the bodies sum each
/// product in one chain (the host net's packed kernels block the sums), and the decoder's first
/// layer stays after the upsampling (infer may move it before: the same values up to rounding).
/// The dynamic graphs are the exact k nearest by BruteForceKnn's ranking key (the direct distance
/// in double, rounded to S; ties by index), whatever Search the net was built with; BruteForceKnn
/// itself agrees except where an item's feature rows nearly coincide (its candidate pass cannot
/// resolve them: README). Not for training: the weights are copied at construction (build a new
/// one after the parameters change).

#include <string>
#include <vector>

#include "../core/host_buffer.hpp"
#include "../core/parallel.hpp"
#include "detail/inference_kernels.hpp"
#include "detail/neighbor_gather.hpp"
#include "super_resolution_net.hpp"

namespace simsr::nn {

template <class S, template <class> class Memory>
class InferenceNet {
 public:
  using scalar_type = S;

  /// Copies `net`'s inference parameters (its upsampling weights prepared under `policy` when not
  /// yet: SuperResolutionNet::prepare_inference). ArgumentError when a BatchNorm has no running
  /// statistics (eval mode would use batch statistics: no fixed inference).
  template <exec::HostPolicy Policy, class Search>
  InferenceNet(Policy policy, SuperResolutionNet<S, Search>& net)
      : cfg_(net.config()), n_(net.lr_points()), m_(net.hr_points()), d_(net.latent_dim()) {
    if (!net.upsampling().has_precomputed_weights()) net.prepare_inference(policy);
    std::vector<S> params;
    // positional table
    const Matrix<S>& table = net.positional_encoding().table();
    pe_dim_ = table.cols();
    table_off_ = append(params, table.data(), table.size());
    // feature embedding
    std::vector<VIndex> fixed_graph;
    Index col = 3 + pe_dim_;
    if (net.has_feature_embedding()) {
      auto& fe = net.feature_embedding();
      for (Index b = 0; b < fe.blocks(); ++b) {
        auto& block = fe.block(b);
        auto& edge = block.edge_conv();
        BlockLayout L;
        L.in = edge.in_features();
        L.out = edge.out_features();
        L.k = edge.k();
        L.in_col = b == 0 ? 0 : col - fe.block(b - 1).edge_conv().out_features();
        L.out_col = col;
        col += L.out;
        if (b == 0 && L.in != 3 + pe_dim_)
          throw ShapeError("nn::InferenceNet: block 0's input (3 + the positional encoding's columns)", {3 + pe_dim_}, {L.in});
        L.dynamic = edge.dynamic();
        if (!L.dynamic) {
          const GraphIndices& g = edge.graph();
          if (g.rows() != n_ || g.cols() != L.k)
            throw ShapeError("nn::InferenceNet: block " + std::to_string(b) + "'s fixed graph (N×k)", {n_, L.k}, {g.rows(), g.cols()});
          L.graph_off = Index(fixed_graph.size());
          fixed_graph.insert(fixed_graph.end(), g.data(), g.data() + g.size());
        }
        Mlp<S>& mlp = edge.edge_function();
        // the first Linear per point: [W_d; W_s − W_d] (2H × C), bias [0, b]
        Linear<S>& first = mlp.linear(0);
        const Index C = L.in, H = first.out_features();
        Matrix<S> point_w(2 * H, C);
        const auto W = first.weight();
        point_w.topRows(H) = W.leftCols(C);
        point_w.bottomRows(H) = W.rightCols(C) - W.leftCols(C);
        std::vector<S> point_b(std::size_t(2 * H), S(0));
        if (first.has_bias())
          for (Index h = 0; h < H; ++h) point_b[std::size_t(H + h)] = first.bias()[h];
        const Matrix<S> point_wt = point_w.transpose();
        L.point = StageLayout{C, 2 * H, append(params, point_wt.data(), point_wt.size()), append(params, point_b.data(), 2 * H), -1,
                              detail::KernelAct::none, S(0)};
        L.first_tail = tail_layout(params, mlp, 0);
        for (Index s = 1; s < mlp.stages(); ++s) L.edge_rest.push_back(stage_layout(params, mlp, s));
        Mlp<S>& fc = block.fc_out();
        for (Index s = 0; s < fc.stages(); ++s) L.fc_out.push_back(stage_layout(params, fc, s));
        blocks_.push_back(std::move(L));
      }
    }
    if (col != d_) throw ShapeError("nn::InferenceNet: the code's columns", {d_}, {col});
    // upsampling
    auto& up = net.upsampling();
    up_k_ = up.neighbors();
    const Matrix<S>& uw = up.inference_weights();
    up_w_off_ = append(params, uw.data(), uw.size());
    // decoder
    auto& dec = net.decoder();
    for (Index s = 0; s < dec.sine_layers().stages(); ++s) decoder_.push_back(stage_layout(params, dec.sine_layers(), s));
    for (Index s = 0; s < dec.output_layer().stages(); ++s) decoder_.push_back(stage_layout(params, dec.output_layer(), s));
    // residual base
    if (cfg_.residual) {
      const bool embedded = cfg_.residual_base == ResidualBase::embedded;
      const auto& map = embedded ? net.residual_embedding() : net.residual_map();
      if (map.rows() == 0)
        throw ArgumentError("nn::InferenceNet: the local-linear residual base is not fitted yet (set_residual_map, or interp::Learned::train)");
      residual_per_coordinate_ = embedded;
      std::vector<Index> starts(std::size_t(map.rows() + 1)), cols;
      std::vector<S> values;
      for (Index r = 0; r < map.rows(); ++r) {
        starts[std::size_t(r)] = Index(cols.size());
        for (typename std::remove_cvref_t<decltype(map)>::InnerIterator it(map, r); it; ++it) {
          cols.push_back(it.index());
          values.push_back(it.value());
        }
      }
      starts.back() = Index(cols.size());
      residual_starts_ = Memory<Index>(Span<const Index>{starts.data(), Index(starts.size())});
      residual_cols_ = Memory<Index>(Span<const Index>{cols.data(), Index(cols.size())});
      residual_values_ = Memory<S>(Span<const S>{values.data(), Index(values.size())});
    }
    params_ = Memory<S>(Span<const S>{params.data(), Index(params.size())});
    graphs_ = Memory<VIndex>(Span<const VIndex>{fixed_graph.data(), Index(fixed_graph.size())});
    const GraphIndices& ui = up.indices();
    up_idx_ = Memory<VIndex>(Span<const VIndex>{ui.data(), ui.size()});
  }

  InferenceNet(const InferenceNet&) = delete;
  InferenceNet& operator=(const InferenceNet&) = delete;
  InferenceNet(InferenceNet&&) noexcept = default;
  InferenceNet& operator=(InferenceNet&&) noexcept = default;

  Index lr_points() const { return n_; }
  Index hr_points() const { return m_; }
  Index latent_dim() const { return d_; }
  const NetworkConfig& config() const { return cfg_; }

  /// pred ((B·M)×3) ← the network's eval prediction from ldx ((B·N)×3), normalized units as
  /// SuperResolutionNet::infer. Both views in this instance's memory space (row-major, row stride
  /// ≥ 3). ShapeError for rows that are not B·N and B·M, or another column count; ArgumentError
  /// for a row stride below 3. Allocates nothing once warm for the same B.
  template <class Policy>
  void infer(Policy policy, MatrixSpan<const S> ldx, MatrixSpan<S> pred) {
    static_assert(PolicyFor<Policy, Memory>,
                  "nn::InferenceNet runs under the policy of its memory: exec::seq or exec::omp for HostBuffer, exec::cuda for DeviceBuffer");
    if (ldx.cols != 3 || ldx.rows < 1 || ldx.rows % n_)
      throw ShapeError("nn::InferenceNet::infer: LR displacements (B·" + std::to_string(n_) + " rows)", {-1, 3}, {ldx.rows, ldx.cols});
    const Index B = ldx.rows / n_;
    if (pred.rows != B * m_ || pred.cols != 3)
      throw ShapeError("nn::InferenceNet::infer: prediction (B·M rows)", {B * m_, 3}, {pred.rows, pred.cols});
    if (ldx.stride < 3 || pred.stride < 3)
      throw ArgumentError("nn::InferenceNet::infer: row strides " + std::to_string(ldx.stride) + " (LR) and " + std::to_string(pred.stride) +
                          " (prediction) for 3 columns");
    reserve(B);
    const Index R = B * n_;
    const MatrixSpan<S> z{z_.span().data, R, d_, d_};
    exec::parallel_for(policy, R * (3 + pe_dim_),
                       detail::PositionalEntries<S>{ldx, table(), {z.data, R, 3 + pe_dim_, d_}});
    for (const BlockLayout& L : blocks_) run_block(policy, L, B, z);
    // upsampling gather: z^H = W·z per item
    const MatrixSpan<S> zh{zh_.span().data, B * m_, d_, d_};
    exec::parallel_for(policy, B * m_ * d_,
                       detail::UpsampleGatherEntries<S>{{up_idx_.span().data, m_, n_, {param(up_w_off_), m_, up_k_, up_k_},
                                                         MatrixSpan<const S>{z.data, R, d_, d_}, zh, 0}});
    run_stages(policy, decoder_, {zh.data, zh.rows, d_, d_}, pred, dec_a_, dec_b_);
    if (cfg_.residual)
      exec::parallel_for(policy, B * m_ * 3,
                         detail::ResidualBaseEntries<S>{residual_starts_.span().data, residual_cols_.span().data, residual_values_.span().data,
                                                        residual_per_coordinate_, n_, m_, ldx, pred});
  }

  /// infer on host arrays: copies ldx in and the prediction out (the device instance's transfers;
  /// the host instance's copies too, so both are called alike). Allocates nothing once warm for
  /// the same B and a pred already (B·M)×3.
  template <class Policy>
  void infer(Policy policy, const ConstView<S>& ldx, Matrix<S>& pred) {
    if (ldx.cols() != 3 || ldx.rows() < 1 || ldx.rows() % n_)
      throw ShapeError("nn::InferenceNet::infer: LR displacements (B·" + std::to_string(n_) + " rows)", {-1, 3}, {ldx.rows(), ldx.cols()});
    const Index B = ldx.rows() / n_;
    const S* rows = ldx.data();
    if (ldx.outerStride() != 3) {  // a column block has a row stride of its own: packed first
      packed_ = ldx;
      rows = packed_.data();
    }
    ldx_.resize(3 * ldx.rows());
    ldx_.copy_from(Span<const S>{rows, 3 * ldx.rows()});
    pred_.resize(B * m_ * 3);
    infer(policy, MatrixSpan<const S>{ldx_.span().data, B * n_, 3, 3}, MatrixSpan<S>{pred_.span().data, B * m_, 3, 3});
    if (pred.rows() != B * m_ || pred.cols() != 3) pred.resize(B * m_, 3);
    pred_.copy_to(Span<S>{pred.data(), pred.size()});
  }

  /// The LR code z = [h⁰, h¹, …] of the last infer ((B·N)×latent_dim), copied to the host;
  /// ArgumentError before an infer.
  Matrix<S> code() const {
    if (batch_ == 0) throw ArgumentError("nn::InferenceNet::code: no infer yet");
    Matrix<S> z(batch_ * n_, d_);
    z_.copy_to(Span<S>{z.data(), z.size()});
    return z;
  }

  /// The dynamic feature-space graph block `b` built in the last infer ((B·N)×k, each item's local
  /// indices), copied to the host; ArgumentError for a block with a fixed graph or before an infer.
  GraphIndices dynamic_graph(Index b) const {
    if (b < 0 || b >= Index(blocks_.size()) || !blocks_[std::size_t(b)].dynamic)
      throw ArgumentError("nn::InferenceNet::dynamic_graph: block " + std::to_string(b) + " has no dynamic graph");
    const BlockLayout& L = blocks_[std::size_t(b)];
    if (batch_ == 0) throw ArgumentError("nn::InferenceNet::dynamic_graph: no infer yet");
    GraphIndices g(batch_ * n_, L.k);
    std::vector<VIndex> all(std::size_t(dyn_graph_.size()));
    dyn_graph_.copy_to(Span<VIndex>{all.data(), Index(all.size())});
    std::copy_n(all.data() + L.dyn_off * graph_slot_, g.size(), g.data());
    return g;
  }

 private:
  /// A Linear (offsets into the parameters, the weight transposed: in×out; -1: none) and its tail.
  struct StageLayout {
    Index in = 0, out = 0, w = -1, bias = -1, bn = -1;
    detail::KernelAct act = detail::KernelAct::none;
    S param = S(0);
  };
  struct BlockLayout {
    Index in = 0, out = 0, k = 0, in_col = 0, out_col = 0;
    bool dynamic = false;
    Index graph_off = 0;  ///< fixed graph: offset in graphs_
    Index dyn_off = 0;    ///< dynamic graph: its slot in dyn_graph_
    StageLayout point;       ///< the first Linear per point (2H outputs), no tail
    StageLayout first_tail;  ///< the first stage's BatchNorm and activation (w unused)
    std::vector<StageLayout> edge_rest, fc_out;
  };

  static Index append(std::vector<S>& params, const S* data, Index n) {
    const Index off = Index(params.size());
    params.insert(params.end(), data, data + n);
    return off;
  }
  static detail::KernelAct kernel_act(Act a) {
    return a == Act::leaky_relu ? detail::KernelAct::leaky_relu : a == Act::sine ? detail::KernelAct::sine : detail::KernelAct::none;
  }
  /// Stage s's BatchNorm (eval transform) and activation.
  static StageLayout tail_layout(std::vector<S>& params, Mlp<S>& mlp, Index s) {
    const MlpStage& spec = mlp.spec(s);
    StageLayout L;
    L.out = spec.out;
    L.act = kernel_act(spec.act);
    L.param = static_cast<S>(spec.act == Act::sine ? spec.omega0 : spec.slope);
    if (spec.batch_norm) {
      const Matrix<S> t = mlp.batch_norm(s).eval_transform();  // row-major 4×C: μ, 1/σ, γ, β
      L.bn = append(params, t.data(), t.size());
    }
    return L;
  }
  static StageLayout stage_layout(std::vector<S>& params, Mlp<S>& mlp, Index s) {
    StageLayout L = tail_layout(params, mlp, s);
    Linear<S>& lin = mlp.linear(s);
    L.in = lin.in_features();
    const Matrix<S> Wt = lin.weight().transpose();  // DenseEntries reads Wᵀ
    L.w = append(params, Wt.data(), Wt.size());
    if (lin.has_bias()) L.bias = append(params, lin.bias().data(), L.out);
    return L;
  }

  const S* param(Index off) const { return off < 0 ? nullptr : params_.span().data + off; }
  MatrixSpan<const S> table() const { return {param(table_off_), n_, pe_dim_, pe_dim_}; }
  detail::StageTail<S> tail(const StageLayout& L) const { return {param(L.bn), L.out, L.act, L.param}; }

  /// Sizes every buffer for B items (nothing when B is the last call's).
  void reserve(Index B) {
    if (B == batch_) return;
    const Index R = B * n_;
    Index edge_w = 1, fc_w = 1, point_w = 1, cat_w = 1, out_w = 1, dyn = 0, kmax = 1;
    for (BlockLayout& L : blocks_) {
      point_w = std::max(point_w, L.point.out);
      edge_w = std::max(edge_w, L.point.out / 2);
      for (const auto& s : L.edge_rest) edge_w = std::max(edge_w, s.out);
      for (const auto& s : L.fc_out) fc_w = std::max(fc_w, s.out);
      cat_w = std::max(cat_w, L.in + 3 * L.out);
      out_w = std::max(out_w, L.out);
      kmax = std::max(kmax, L.k);
      if (L.dynamic) L.dyn_off = dyn++;
    }
    Index dec_w = 1;
    for (const auto& s : decoder_) dec_w = std::max(dec_w, s.out);
    z_.resize(R * d_);
    if (!blocks_.empty()) {
      point_.resize(R * point_w);
      edges_a_.resize(R * kmax * edge_w);
      edges_b_.resize(R * kmax * edge_w);
      edge_out_.resize(R * kmax * out_w);
      e_.resize(R * out_w);
      pool_max_.resize(B * out_w);
      pool_mean_.resize(B * out_w);
      cat_.resize(R * cat_w);
      fc_a_.resize(R * fc_w);
      fc_b_.resize(R * fc_w);
      graph_slot_ = R * kmax;
      dyn_graph_.resize(dyn * graph_slot_);
      knn_d_.resize(R * kmax);
    }
    zh_.resize(B * m_ * d_);
    dec_a_.resize(B * m_ * dec_w);
    dec_b_.resize(B * m_ * dec_w);
    batch_ = B;
  }

  /// The stages one after the other: stage i < last into a (i even) or b (i odd), the last into y.
  template <class Policy>
  void run_stages(Policy policy, const std::vector<StageLayout>& stages, MatrixSpan<const S> x, MatrixSpan<S> y, Memory<S>& a, Memory<S>& b) {
    const Index rows = x.rows;
    for (std::size_t i = 0; i < stages.size(); ++i) {
      const StageLayout& L = stages[i];
      const bool last = i + 1 == stages.size();
      const MatrixSpan<S> out = last ? y : MatrixSpan<S>{(i % 2 ? b : a).span().data, rows, L.out, L.out};
      exec::parallel_for(policy, rows * L.out, detail::DenseEntries<S>{x, param(L.w), param(L.bias), tail(L), out});
      x = {out.data, out.rows, out.cols, out.stride};
    }
  }

  /// One embedding block: its input and output are column blocks of z.
  template <class Policy>
  void run_block(Policy policy, const BlockLayout& L, Index B, MatrixSpan<S> z) {
    const Index R = B * n_, k = L.k, H = L.point.out / 2;
    const MatrixSpan<const S> h{z.data + L.in_col, R, L.in, z.stride};
    detail::GraphRows graph{graphs_.span().data + L.graph_off, n_, k, n_};
    if (L.dynamic) {
      VIndex* g = dyn_graph_.span().data + L.dyn_off * graph_slot_;
      exec::parallel_for(policy, R, detail::FeatureKnnRows<S>{h, n_, k, g, knn_d_.span().data});
      graph = {g, R, k, n_};
    }
    const MatrixSpan<S> P{point_.span().data, R, 2 * H, 2 * H};
    exec::parallel_for(policy, R * 2 * H, detail::DenseEntries<S>{h, param(L.point.w), param(L.point.bias), {}, P});
    const MatrixSpan<S> first{edges_a_.span().data, R * k, H, H};
    exec::parallel_for(policy, R * k * H, detail::EdgeFirstLayerEntries<S>{{P.data, R, 2 * H, 2 * H}, graph, tail(L.first_tail), first});
    MatrixSpan<const S> edge_values{first.data, first.rows, first.cols, first.stride};
    if (!L.edge_rest.empty()) {
      const MatrixSpan<S> eo{edge_out_.span().data, R * k, L.out, L.out};
      run_stages(policy, L.edge_rest, edge_values, eo, edges_b_, edges_a_);
      edge_values = {eo.data, eo.rows, eo.cols, eo.stride};
    }
    const MatrixSpan<S> e{e_.span().data, R, L.out, L.out};
    exec::parallel_for(policy, R * L.out, detail::EdgeMaxEntries<S>{edge_values, k, e});
    const MatrixSpan<S> mx{pool_max_.span().data, B, L.out, L.out}, mean{pool_mean_.span().data, B, L.out, L.out};
    exec::parallel_for(policy, B * L.out, detail::ItemPoolEntries<S>{{e.data, R, L.out, L.out}, n_, mx, mean});
    const Index W = L.in + 3 * L.out;
    const MatrixSpan<S> cat{cat_.span().data, R, W, W};
    exec::parallel_for(policy, R * W,
                       detail::BlockConcatEntries<S>{h, {e.data, R, L.out, L.out}, {mx.data, B, L.out, L.out}, {mean.data, B, L.out, L.out}, n_, cat});
    run_stages(policy, L.fc_out, {cat.data, R, W, W}, {z.data + L.out_col, R, L.out, z.stride}, fc_a_, fc_b_);
  }

  NetworkConfig cfg_;
  Index n_, m_, d_, pe_dim_ = 0, up_k_ = 0;
  Index table_off_ = -1, up_w_off_ = -1;
  std::vector<BlockLayout> blocks_;
  std::vector<StageLayout> decoder_;
  bool residual_per_coordinate_ = true;
  Memory<S> params_;
  Memory<VIndex> graphs_, up_idx_, dyn_graph_;
  Memory<Index> residual_starts_, residual_cols_;
  Memory<S> residual_values_;
  Memory<S> z_, point_, edges_a_, edges_b_, edge_out_, e_, pool_max_, pool_mean_, cat_, fc_a_, fc_b_, knn_d_, zh_, dec_a_, dec_b_;
  Memory<S> ldx_, pred_;  ///< infer on host arrays: the transfers' buffers
  Matrix<S> packed_;      ///< infer on host arrays with a row stride other than 3: the rows packed
  Index batch_ = 0;       ///< B the buffers are sized for (0: none yet)
  Index graph_slot_ = 0;  ///< entries of one dynamic graph's slot in dyn_graph_ (B·N·max k)
};

/// The host instance: the device path's launches under exec::seq / exec::omp.
template <class S = float>
using HostInferenceNet = InferenceNet<S, HostBuffer>;

#if defined(__CUDACC__)
/// The device instance (nvcc only): the same launches under exec::cuda.
template <class S = float>
using DeviceInferenceNet = InferenceNet<S, DeviceBuffer>;

/// `net`'s inference on the device (its upsampling weights prepared under `policy` when not yet).
template <exec::HostPolicy Policy, class S, class Search>
DeviceInferenceNet<S> to_device(Policy policy, SuperResolutionNet<S, Search>& net) {
  return DeviceInferenceNet<S>(policy, net);
}
#endif

}  // namespace simsr::nn
