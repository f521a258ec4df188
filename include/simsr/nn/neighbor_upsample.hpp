#pragma once
/// \file
/// Neighbour upsampling (paper §3.2, Eq. 1; SPEC §7 `upsampling`): every HR vertex j blends the
/// latent codes of its upK LR neighbours idx(j, 0..upK−1) with softmax weights,
/// z_j^H = Σ_i w_ji z^L_{idx(j,i)}, w_j· = softmax(logits_j·) (logits from the weighting MLP).
///
///     nn::NeighborUpsample<float> up(up_indices, N);     // up_indices: M×upK, into [0, N)
///     up.forward(exec::omp, logits, zL, zH);                  // logits M×upK, zL (B·N)×C → zH (B·M)×C
///     up.backward(exec::omp, zL, d_zH, &d_logits, &d_zL);
///     // inference: weights depend on rest shapes only
///     nn::NeighborUpsample<float>::softmax_rows(exec::omp, logits, w);   // once
///     up.apply(exec::omp, w, zL, zH);                                     // every frame: weighted gather only

#include <cmath>
#include <string>

#include "batch_split.hpp"
#include "detail/neighbor_gather.hpp"
#include "graph_features.hpp"
#include "layer.hpp"

namespace simsr::nn {

/// Softmax-weighted gather of LR codes to HR vertices (Eq. 1). The weights (and logits) have M
/// rows, shared by every batch item (the official network: the query depends on rest shapes
/// only), or B·M rows, one block of M per item. Row b·M + j of the output is HR vertex j of item b;
/// row b·N + n of z is LR point n of item b. Backward gathers per LR point over a reverse
/// adjacency and sums shared-weight gradients over items in order: exec::seq and exec::omp agree
/// bitwise. Warm calls allocate nothing. The gather is detail::UpsampleGather, the body
/// DeviceNeighborUpsample (device_neighbor_upsample.hpp) runs under exec::cuda.
template <class S = float>
class NeighborUpsample {
 public:
  using scalar_type = S;

  /// indices: M×upK LR neighbours of each HR vertex, each in [0, lr_points). ArgumentError otherwise.
  NeighborUpsample(const GraphIndices& indices, Index lr_points) : idx_(indices), n_(lr_points) {
    if (indices.rows() < 1 || indices.cols() < 1 || lr_points < 1)
      throw ArgumentError("nn::NeighborUpsample: needs M >= 1 HR vertices, upK >= 1 neighbours and N >= 1 LR points");
    for (Index i = 0; i < idx_.size(); ++i)
      if (idx_.data()[i] < 0 || idx_.data()[i] >= n_)
        throw ArgumentError("nn::NeighborUpsample: neighbour index " + std::to_string(idx_.data()[i]) + " (HR vertex " +
                            std::to_string(i / idx_.cols()) + ") is outside [0, " + std::to_string(n_) + ")");
    rev_.build(n_, idx_.size(), [&](Index e) { return Index(idx_.data()[e]); });
  }

  Index hr_points() const { return idx_.rows(); }
  Index lr_points() const { return n_; }
  Index neighbors() const { return idx_.cols(); }
  const GraphIndices& indices() const { return idx_; }
  /// Softmax weights of the last forward (M×upK or (B·M)×upK).
  const Matrix<S>& weights() const { return w_; }

  /// w = row-wise softmax of `logits` (max subtracted, sum in double).
  template <exec::HostPolicy Policy>
  static void softmax_rows(Policy policy, const ConstView<S>& logits, Matrix<S>& w) {
    const Index R = logits.rows(), K = logits.cols();
    ensure_shape(w, R, K);
    const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, R, nc, workers, [&](Index, Index, Index b, Index e) {
      for (Index r = b; r < e; ++r) {
        const S m = logits.row(r).maxCoeff();
        double sum = 0;
        for (Index i = 0; i < K; ++i) sum += double(w(r, i) = std::exp(logits(r, i) - m));
        const S inv = static_cast<S>(1.0 / sum);
        for (Index i = 0; i < K; ++i) w(r, i) *= inv;
      }
    });
  }

  /// Training path: weights ← softmax(logits), then apply(policy, weights, z, out).
  template <exec::HostPolicy Policy>
  void forward(Policy policy, const ConstView<S>& logits, const ConstView<S>& z, Matrix<S>& out) {
    check_weights("logits", logits, check_z(z));
    softmax_rows(policy, logits, w_);
    apply(policy, w_, z, out);
  }

  /// Inference path (and the gather of forward): out (B·M)×C, out_{b,j} = Σ_i w_ji z_{b, idx(j,i)}
  /// with precomputed weights (M×upK shared, or (B·M)×upK), summed in ascending i.
  template <exec::HostPolicy Policy>
  void apply(Policy policy, const ConstView<S>& weights, const ConstView<S>& z, Matrix<S>& out) const {
    const Index B = check_z(z), M = idx_.rows();
    check_weights("weights", weights, B);
    ensure_shape(out, B * M, z.cols());
    const Index rows = B * M;
    const Index nc = exec::chunk_count(rows, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, rows, nc, workers,
                     [&](Index, Index, Index b, Index e) { gather_rows(weights, z, b, e, out.data() + b * out.cols(), out.cols()); });
  }

  /// apply's rows [begin, end) alone, written to `out` (row-major, leading dimension ld_out ≥
  /// z.cols()), the same arithmetic: for a caller that consumes the upsampled rows chunk by chunk
  /// while they are in cache (SuperResolutionNet's inference gathers the decoder's first-layer
  /// products into the decoder's own row chunks). ShapeError / ArgumentError for shapes or a range
  /// that apply would refuse.
  void apply_rows(const ConstView<S>& weights, const ConstView<S>& z, Index begin, Index end, S* out, Index ld_out) const {
    const Index B = check_z(z);
    check_weights("weights", weights, B);
    if (begin < 0 || end < begin || end > B * idx_.rows() || ld_out < z.cols())
      throw ArgumentError("nn::NeighborUpsample::apply_rows: rows [" + std::to_string(begin) + ", " + std::to_string(end) + ") of " +
                          std::to_string(B * idx_.rows()) + " with leading dimension " + std::to_string(ld_out) + " for " +
                          std::to_string(z.cols()) + " columns");
    gather_rows(weights, z, begin, end, out, ld_out);
  }

  /// After forward(policy, logits, z, …): d_logits (shape of the logits) = w ⊙ (dw − Σ_i w dw) with
  /// dw_ji = Σ_b d_out_{b,j}·z_{b,idx(j,i)} (the sum over b only for shared logits), and
  /// d_z_{b,n} = Σ_{(j,i): idx(j,i)=n} w_ji d_out_{b,j}. Either output may be null; both are overwritten.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& z, const ConstView<S>& d_out, Matrix<S>* d_logits, Matrix<S>* d_z) {
    const Index B = check_z(z), M = idx_.rows(), K = idx_.cols(), C = z.cols();
    if (w_.size() == 0) throw ArgumentError("nn::NeighborUpsample: backward needs a forward first");
    const bool shared = check_weights("weights (last forward)", w_, B);
    detail::check_shape("nn::NeighborUpsample", "output gradient", d_out, B * M, C);
    if (d_logits && shared && split_ && split_->size() > 1) {  // one process: the loop below, the same bits
      split_logit_gradient(policy, z, d_out, *d_logits);
    } else if (d_logits) {
      const Index R = w_.rows();
      ensure_shape(*d_logits, R, K);
      const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
      exec::for_chunks(policy, R, nc, workers, [&](Index, Index, Index b, Index e) {
        for (Index r = b; r < e; ++r) {
          const Index j = r % M, item0 = shared ? 0 : r / M, item1 = shared ? B : item0 + 1;
          auto dl = d_logits->row(r);
          S dot = 0;
          for (Index i = 0; i < K; ++i) {
            S dw = 0;
            for (Index item = item0; item < item1; ++item) dw += d_out.row(item * M + j).dot(z.row(item * n_ + idx_(j, i)));
            dl[i] = dw;
            dot += w_(r, i) * dw;
          }
          for (Index i = 0; i < K; ++i) dl[i] = w_(r, i) * (dl[i] - dot);
        }
      });
    }
    if (d_z) {
      ensure_shape(*d_z, B * n_, C);
      const Index rows = B * n_;
      const Index nc = exec::chunk_count(rows, product_chunks), workers = exec::worker_count(policy, nc);
      exec::for_chunks(policy, rows, nc, workers, [&](Index, Index, Index b, Index e) {
        for (Index r = b; r < e; ++r) {
          const Index item = r / n_, n = r % n_;
          auto g = d_z->row(r);
          g.setZero();
          for (Index s = rev_.start[std::size_t(n)]; s < rev_.start[std::size_t(n + 1)]; ++s) {
            const Index edge = rev_.edges[std::size_t(s)], j = edge / K, i = edge % K;
            g += w_(shared ? j : item * M + j, i) * d_out.row(item * M + j);
          }
        }
      });
    }
  }

  /// The batch split of data-parallel training (nullptr: none): the gradient of shared logits, a
  /// sum over the batch items, is then summed over the global batch's items in order (on one
  /// process the loop over items already adds them in that order).
  void set_batch_split(BatchSplit* split) { split_ = split; }

 private:
  /// d_logits under a batch split: dw per local item (count × M·upK), gathered, summed over the
  /// global items in order from 0 (the order of the loop above), then the softmax's backward.
  template <class Policy>
  void split_logit_gradient(Policy policy, const ConstView<S>& z, const ConstView<S>& d_out, Matrix<S>& d_logits) {
    const Index M = idx_.rows(), K = idx_.cols(), L = split_->count();
    split_->rows_per_item(z.rows(), "nn::NeighborUpsample");  // checks that z holds this rank's items
    ensure_shape(item_dw_, L, M * K);
    const Index nc = exec::chunk_count(M, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, M, nc, workers, [&](Index, Index, Index b, Index e) {
      for (Index item = 0; item < L; ++item)
        for (Index j = b; j < e; ++j)
          for (Index i = 0; i < K; ++i) item_dw_(item, j * K + i) = d_out.row(item * M + j).dot(z.row(item * n_ + idx_(j, i)));
    });
    const S* all = split_->gather(item_dw_.data(), M * K);
    const Index items = split_->items();
    ensure_shape(d_logits, M, K);
    exec::for_chunks(policy, M, nc, workers, [&](Index, Index, Index b, Index e) {
      for (Index j = b; j < e; ++j) {
        auto dl = d_logits.row(j);
        S dot = 0;
        for (Index i = 0; i < K; ++i) {
          S dw = 0;
          for (Index item = 0; item < items; ++item) dw += all[item * M * K + j * K + i];
          dl[i] = dw;
          dot += w_(j, i) * dw;
        }
        for (Index i = 0; i < K; ++i) dl[i] = w_(j, i) * (dl[i] - dot);
      }
    });
  }

  /// Rows [b, e) of the gather into out (row b first, leading dimension ld_out), shapes checked:
  /// the device twin's body, row by row.
  void gather_rows(const ConstView<S>& weights, const ConstView<S>& z, Index b, Index e, S* out, Index ld_out) const {
    const detail::UpsampleGather<S> body{idx_.data(),
                                         idx_.rows(),
                                         n_,
                                         {weights.data(), weights.rows(), weights.cols(), weights.outerStride()},
                                         {z.data(), z.rows(), z.cols(), z.outerStride()},
                                         {out, e - b, z.cols(), ld_out},
                                         b};
    for (Index r = b; r < e; ++r) body(r);
  }

  /// Number of batch items B of z ((B·N)×C); ShapeError otherwise.
  Index check_z(const ConstView<S>& z) const {
    if (z.rows() % n_ || z.cols() < 1)
      throw ShapeError("nn::NeighborUpsample: LR codes (B·" + std::to_string(n_) + " rows)", {-1, z.cols()}, {z.rows(), z.cols()});
    return z.rows() / n_;
  }
  /// True for shared (M rows), false for per-item (B·M rows); ShapeError otherwise.
  template <class W>
  bool check_weights(const char* what, const W& w, Index B) const {
    const Index M = idx_.rows();
    if (w.cols() != idx_.cols() || (w.rows() != M && w.rows() != B * M))
      throw ShapeError(std::string("nn::NeighborUpsample: ") + what + " (M or B·M rows)", {M, idx_.cols()}, {w.rows(), w.cols()});
    return w.rows() == M;
  }

  GraphIndices idx_;
  Index n_;
  detail::ReverseAdjacency rev_;
  Matrix<S> w_;
  BatchSplit* split_ = nullptr;
  Matrix<S> item_dw_;
};

}  // namespace simsr::nn
