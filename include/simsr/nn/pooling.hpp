#pragma once
/// \file
/// Max and mean pooling over consecutive groups of rows, optionally broadcast back to every row.
/// SPEC §7: the global max and mean over the points of each batch item (group = N points,
/// broadcast: the reference's adaptive_max/avg_pool1d + repeat), and the EdgeConv max over the k
/// edges of each point (group = k, no broadcast: rows (b·N + n)·k + j → row b·N + n).
///
///     nn::GroupPool<float> gmax(nn::PoolKind::max, N);          // (B·N)×C → (B·N)×C, broadcast
///     nn::GroupPool<float> emax(nn::PoolKind::max, k, false);   // (B·N·k)×C → (B·N)×C

#include <vector>

#include "layer.hpp"

namespace simsr::nn {

enum class PoolKind { max, mean };

/// Pools each channel over each group of `group_size` consecutive rows. Max backward routes the
/// gradient to the first row holding the maximum (ties: lowest row); mean spreads it evenly.
/// With `broadcast` the output has the input's rows (each row gets its group's value) and the
/// gradient of a group is the sum over its rows; without, one output row per group.
template <class S = float>
class GroupPool {
 public:
  using scalar_type = S;

  GroupPool(PoolKind kind, Index group_size, bool broadcast = true) : kind_(kind), g_(group_size), broadcast_(broadcast) {
    if (group_size < 1) throw ArgumentError("nn::GroupPool: group_size must be >= 1");
  }

  PoolKind kind() const { return kind_; }
  Index group_size() const { return g_; }
  bool broadcast() const { return broadcast_; }
  Index out_features(Index in_cols) const { return in_cols; }
  using ArgmaxIndices = Eigen::Matrix<Index, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

  /// Row within its group of each group's maximum, groups × C (max pooling, last forward).
  const ArgmaxIndices& argmax() const { return argmax_; }
  /// Routes the next backward's gradient through `rows` (groups × C, each within its group)
  /// instead of the first maxima the forward found: at tied maxima the gradient is a choice of
  /// subgradient, and this makes another implementation's choice (PyTorch's, in the interop test,
  /// where float32 rounding breaks near-ties the other way). The next forward finds its own again.
  /// ArgumentError for mean pooling, before a forward, for another shape or a row outside its group.
  void set_argmax(const ArgmaxIndices& rows) {
    if (kind_ != PoolKind::max) throw ArgumentError("nn::GroupPool::set_argmax: mean pooling has no maxima");
    if (rows.rows() != argmax_.rows() || rows.cols() != argmax_.cols())
      throw ShapeError("nn::GroupPool::set_argmax: the last forward's groups × channels", {argmax_.rows(), argmax_.cols()}, {rows.rows(), rows.cols()});
    for (Index g = 0; g < rows.rows(); ++g)
      for (Index c = 0; c < rows.cols(); ++c)
        if (rows(g, c) < 0 || rows(g, c) >= g_)
          throw ArgumentError("nn::GroupPool::set_argmax: group " + std::to_string(g) + ", channel " + std::to_string(c) + ": row " +
                              std::to_string(rows(g, c)) + " outside [0, " + std::to_string(g_) + ")");
    argmax_ = rows;
  }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode, const ConstView<S>& in, Matrix<S>& out) {
    const Index groups = check_rows(in), C = in.cols();
    ensure_shape(out, broadcast_ ? in.rows() : groups, C);
    if (kind_ == PoolKind::max && (argmax_.rows() != groups || argmax_.cols() != C)) argmax_.resize(groups, C);
    ensure_size(pooled_, groups * C);
    if (kind_ == PoolKind::mean) reserve_sums(policy, sums_, groups, C);
    // The rows of a group are visited in order, all channels side by side (contiguous, so the
    // loops vectorize); per channel that is the order of the scalar definition: max replaces on
    // strictly greater (the first maximum wins), mean sums in double in ascending rows.
    each_group(policy, groups, [&](Index w, Index g) {
      const Index n = C, G = g_, r0 = g * G;  // locals: the index stores below cannot alias them
      S* p = pooled_.data() + g * n;
      if (kind_ == PoolKind::max) {
        Index* am = argmax_.row(g).data();
        const S* x0 = in.row(r0).data();
        for (Index c = 0; c < n; ++c) p[c] = x0[c], am[c] = 0;
        for (Index j = 1; j < G; ++j) {
          const S* x = in.row(r0 + j).data();
          for (Index c = 0; c < n; ++c)
            if (x[c] > p[c]) p[c] = x[c], am[c] = j;
        }
      } else {
        double* acc = sums_[std::size_t(w)].data();
        for (Index c = 0; c < n; ++c) acc[c] = 0;
        for (Index j = 0; j < G; ++j) {
          const S* x = in.row(r0 + j).data();
          for (Index c = 0; c < n; ++c) acc[c] += double(x[c]);
        }
        for (Index c = 0; c < n; ++c) p[c] = static_cast<S>(acc[c] / double(G));
      }
      if (broadcast_)
        for (Index j = 0; j < g_; ++j) out.row(r0 + j) = ConstMatrixMap<S>(p, 1, C);
      else
        out.row(g) = ConstMatrixMap<S>(p, 1, C);
    });
  }

  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>&, const ConstView<S>& d_out, Matrix<S>* d_in) {
    const Index groups = check_rows(in), C = in.cols();
    detail::check_shape("nn::GroupPool", "output gradient", d_out, broadcast_ ? in.rows() : groups, C);
    if (kind_ == PoolKind::max && argmax_.rows() != groups) throw ArgumentError("nn::GroupPool: backward needs the forward of the same input first");
    if (!d_in) return;
    ensure_shape(*d_in, in.rows(), C);
    if (broadcast_) reserve_sums(policy, grads_, groups, C);
    each_group(policy, groups, [&](Index w, Index g) {
      const Index n = C, G = g_, r0 = g * G;
      // the group's gradient per channel: with broadcast the sum over its rows (in S, ascending)
      const S* grad;
      if (broadcast_) {
        S* acc = grads_[std::size_t(w)].data();
        for (Index c = 0; c < n; ++c) acc[c] = S(0);
        for (Index j = 0; j < G; ++j) {
          const S* d = d_out.row(r0 + j).data();
          for (Index c = 0; c < n; ++c) acc[c] += d[c];
        }
        grad = acc;
      } else {
        grad = d_out.row(g).data();
      }
      if (kind_ == PoolKind::max) {
        d_in->middleRows(r0, G).setZero();
        const Index* am = argmax_.row(g).data();
        for (Index c = 0; c < n; ++c) (*d_in)(r0 + am[c], c) = grad[c];
      } else {
        for (Index j = 0; j < G; ++j) {
          S* d = d_in->row(r0 + j).data();
          for (Index c = 0; c < n; ++c) d[c] = grad[c] / S(G);
        }
      }
    });
  }

 private:
  Index check_rows(const ConstView<S>& in) const {
    if (in.rows() % g_)
      throw ShapeError("nn::GroupPool: input rows (groups × " + std::to_string(g_) + ")", {-1, in.cols()}, {in.rows(), in.cols()});
    return in.rows() / g_;
  }
  /// body(worker, group) for every group, over fixed chunks of groups.
  template <class Policy, class Body>
  void each_group(Policy policy, Index groups, Body&& body) {
    const Index nc = exec::chunk_count(groups, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, groups, nc, workers, [&](Index w, Index, Index b, Index e) {
      for (Index g = b; g < e; ++g) body(w, g);
    });
  }
  /// One C-vector per worker of each_group.
  template <class Policy, class T>
  static void reserve_sums(Policy policy, std::vector<Vector<T>>& v, Index groups, Index C) {
    const Index workers = exec::worker_count(policy, exec::chunk_count(groups, product_chunks));
    if (v.size() < std::size_t(workers)) v.resize(std::size_t(workers));
    for (Index w = 0; w < workers; ++w) ensure_size(v[std::size_t(w)], C);
  }

  PoolKind kind_;
  Index g_;
  bool broadcast_;
  ArgmaxIndices argmax_;
  Vector<S> pooled_;
  std::vector<Vector<double>> sums_;  ///< per worker: the channel sums of a mean group (forward)
  std::vector<Vector<S>> grads_;      ///< per worker: a broadcast group's gradient (backward)
};
static_assert(assert_layer<GroupPool<float>>());

}  // namespace simsr::nn
