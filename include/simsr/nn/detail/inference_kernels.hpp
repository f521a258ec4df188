#pragma once
/// \file
/// The kernel bodies of nn::InferenceNet, the network's whole eval forward as launches of
/// SIMSR_HOST_DEVICE functors over Span / MatrixSpan views: one index an output entry (or a
/// query row), so the same body runs under exec::seq and exec::omp on host arrays and under
/// exec::cuda on device arrays. Plain loops, no Eigen: what a thread of a device does.

#include <cmath>

#include "../../core/device_buffer.hpp"
#include "../../core/host_device.hpp"
#include "../../core/types.hpp"

namespace simsr::nn::detail {

/// A stage's activation (nn::Act's values, as a device body reads them).
enum class KernelAct : int { none = 0, leaky_relu = 1, sine = 2 };

/// What follows a stage's Linear: eval BatchNorm ((y − μ)·(1/σ), then ·γ + β: BatchNorm1d's
/// arithmetic) when `bn` is set (4×out: μ, 1/σ, γ, β), then the activation.
template <class S>
struct StageTail {
  const S* bn = nullptr;
  Index out = 0;
  KernelAct act = KernelAct::none;
  S param = S(0);  ///< LeakyReLU's slope or the sine's ω₀

  SIMSR_HOST_DEVICE S operator()(S y, Index o) const {
    if (bn) {
      y = (y - bn[o]) * bn[out + o];
      y = y * bn[2 * out + o] + bn[3 * out + o];
    }
    if (act == KernelAct::leaky_relu) return y > S(0) ? y : param * y;
    if (act == KernelAct::sine) return std::sin(param * y);
    return y;
  }
};

/// A Linear and its tail, entry k = r·out + o: y(r, o) = tail(b_o + Σ_c x(r, c)·W(o, c)), the sum
/// over c ascending. The weight is stored transposed, Wᵀ in×out row-major, so the threads of a
/// warp (consecutive o of one row) read consecutive addresses of it; `bias` may be null.
template <class S>
struct DenseEntries {
  MatrixSpan<const S> x;
  const S* wt = nullptr;
  const S* bias = nullptr;
  StageTail<S> tail;
  MatrixSpan<S> y;

  SIMSR_HOST_DEVICE void operator()(Index k) const {
    const Index out = y.cols, in = x.cols, r = k / out, o = k % out;
    const S* xr = x.data + r * x.stride;
    S acc = bias ? bias[o] : S(0);
    for (Index c = 0; c < in; ++c) acc += xr[c] * wt[c * out + o];
    y.data[r * y.stride + o] = tail(acc, o);
  }
};

/// h⁰ = [Δx, PE(row mod N)] (nn::PositionalEncoding), entry k = r·(3 + D) + c, into `h0`.
template <class S>
struct PositionalEntries {
  MatrixSpan<const S> ldx;    ///< (B·N)×3
  MatrixSpan<const S> table;  ///< N×D
  MatrixSpan<S> h0;           ///< (B·N)×(3 + D)

  SIMSR_HOST_DEVICE void operator()(Index k) const {
    const Index C = h0.cols, r = k / C, c = k % C;
    h0.data[r * h0.stride + c] = c < 3 ? ldx.data[r * ldx.stride + c] : table.data[(r % table.rows) * table.stride + c - 3];
  }
};

/// Neighbour j of row r (B·N rows, items of N points): the graph holds each item's local indices,
/// N×k shared by every item or (B·N)×k one row per row.
struct GraphRows {
  const VIndex* graph = nullptr;
  Index graph_rows = 0, k = 0, points_per_item = 0;

  SIMSR_HOST_DEVICE Index neighbour(Index r, Index j) const {
    const Index N = points_per_item, item = r / N;
    return item * N + Index(graph[(graph_rows == N ? r % N : r) * k + j]);
  }
};

/// EdgeConv's first Linear per point, then its tail per edge (EdgeConv::forward_point_wise):
/// with P = h·[W_d; W_s − W_d]ᵀ + [0, b] (P: (B·N)×2H, the bias on the point's half), edge row
/// r·k + j, channel c is tail(P(nbr, c) + P(r, H + c)). Entry k = (r·k + j)·H + c.
template <class S>
struct EdgeFirstLayerEntries {
  MatrixSpan<const S> point_terms;  ///< (B·N)×2H
  GraphRows graph;
  StageTail<S> tail;
  MatrixSpan<S> edges;  ///< (B·N·k)×H

  SIMSR_HOST_DEVICE void operator()(Index e) const {
    const Index H = edges.cols, row = e / H, c = e % H, r = row / graph.k, j = row % graph.k;
    const S sum = point_terms.data[graph.neighbour(r, j) * point_terms.stride + c] + point_terms.data[r * point_terms.stride + H + c];
    edges.data[row * edges.stride + c] = tail(sum, c);
  }
};

/// The max over each row's k edge rows (GroupPool's max: the first maximum wins), entry r·C + c.
template <class S>
struct EdgeMaxEntries {
  MatrixSpan<const S> edges;  ///< (R·k)×C
  Index k = 0;
  MatrixSpan<S> out;  ///< R×C

  SIMSR_HOST_DEVICE void operator()(Index e) const {
    const Index C = out.cols, r = e / C, c = e % C;
    S m = edges.data[r * k * edges.stride + c];
    for (Index j = 1; j < k; ++j) {
      const S v = edges.data[(r * k + j) * edges.stride + c];
      if (v > m) m = v;
    }
    out.data[r * out.stride + c] = m;
  }
};

/// An embedding block's global max and mean over each item's N rows (GroupPool: max replaces on
/// strictly greater, mean sums in double in ascending rows), entry b·C + c into B×C arrays.
template <class S>
struct ItemPoolEntries {
  MatrixSpan<const S> e;  ///< (B·N)×C
  Index points_per_item = 0;
  MatrixSpan<S> max, mean;  ///< B×C each

  SIMSR_HOST_DEVICE void operator()(Index k) const {
    const Index C = e.cols, b = k / C, c = k % C, N = points_per_item;
    const S* col = e.data + b * N * e.stride + c;
    S m = col[0];
    double sum = 0;
    for (Index n = 0; n < N; ++n) {
      const S v = col[n * e.stride];
      if (v > m) m = v;
      sum += double(v);
    }
    max.data[b * max.stride + c] = m;
    mean.data[b * mean.stride + c] = static_cast<S>(sum / double(N));
  }
};

/// fc_out's input cat(h, e, max, mean) of an embedding block, entry r·(in + 3·out) + c.
template <class S>
struct BlockConcatEntries {
  MatrixSpan<const S> h, e, max, mean;  ///< (B·N)×in, (B·N)×out, B×out, B×out
  Index points_per_item = 0;
  MatrixSpan<S> cat;

  SIMSR_HOST_DEVICE void operator()(Index k) const {
    const Index W = cat.cols, r = k / W, c = k % W, in = h.cols, out = e.cols, b = r / points_per_item;
    S v;
    if (c < in)
      v = h.data[r * h.stride + c];
    else if (c < in + out)
      v = e.data[r * e.stride + c - in];
    else if (c < in + 2 * out)
      v = max.data[b * max.stride + c - in - out];
    else
      v = mean.data[b * mean.stride + c - in - 2 * out];
    cat.data[r * cat.stride + c] = v;
  }
};

/// The dynamic feature-space graph (nn::DynamicKnnGraph with neighbors::BruteForceKnn), one query
/// row r per index: the k nearest *other* rows of its item by the direct distance
/// S(√Σ_c (h_r,c − h_j,c)²), the sum in double over c ascending (BruteForceKnn's reported
/// distances, the key it ranks by), ties by ascending index. The row's k best are kept sorted in
/// its own row of `graph` (local indices) and `distances` by insertion, so no scratch beyond them.
template <class S>
struct FeatureKnnRows {
  MatrixSpan<const S> h;  ///< (B·N)×C
  Index points_per_item = 0, k = 0;
  VIndex* graph = nullptr;  ///< (B·N)×k
  S* distances = nullptr;   ///< (B·N)×k

  SIMSR_HOST_DEVICE void operator()(Index r) const {
    const Index N = points_per_item, item = r / N, self = r % N, C = h.cols;
    const S* q = h.data + r * h.stride;
    VIndex* gi = graph + r * k;
    S* gd = distances + r * k;
    Index filled = 0;
    for (Index n = 0; n < N; ++n) {
      if (n == self) continue;
      const S* p = h.data + (item * N + n) * h.stride;
      double acc = 0;
      for (Index c = 0; c < C; ++c) {
        const double diff = double(q[c]) - double(p[c]);
        acc += diff * diff;
      }
      const S d = static_cast<S>(std::sqrt(acc));
      // n ascending: an equal distance already kept has the lower index and stays first
      if (filled == k && !(d < gd[k - 1])) continue;
      Index pos = filled < k ? filled++ : k - 1;
      while (pos > 0 && d < gd[pos - 1]) {
        gd[pos] = gd[pos - 1];
        gi[pos] = gi[pos - 1];
        --pos;
      }
      gd[pos] = d;
      gi[pos] = VIndex(n);
    }
  }
};

/// pred(r, c) += the residual base's prediction: a CSR matrix over the LR displacements of the
/// row's item, entry k = r·3 + c (r = b·M + v). `per_coordinate` (the embedding, M×N): row v,
/// column j reads ldx(b·N + j, c); otherwise (the local-linear map, 3M×3N): row 3v + c, column
/// 3j + a reads ldx(b·N + j, a).
template <class S>
struct ResidualBaseEntries {
  const Index* row_start = nullptr;  ///< rows + 1 offsets
  const Index* cols = nullptr;
  const S* values = nullptr;
  bool per_coordinate = true;
  Index lr_points = 0, hr_points = 0;
  MatrixSpan<const S> ldx;  ///< (B·N)×3
  MatrixSpan<S> pred;       ///< (B·M)×3

  SIMSR_HOST_DEVICE void operator()(Index k) const {
    const Index r = k / 3, c = k % 3, b = r / hr_points, v = r % hr_points;
    const Index row = per_coordinate ? v : 3 * v + c;
    const S* base = ldx.data + b * lr_points * ldx.stride;
    S acc = S(0);
    for (Index t = row_start[row]; t < row_start[row + 1]; ++t)
      acc += per_coordinate ? values[t] * base[cols[t] * ldx.stride + c] : values[t] * base[(cols[t] / 3) * ldx.stride + cols[t] % 3];
    pred.data[r * pred.stride + c] += acc;
  }
};

}  // namespace simsr::nn::detail
