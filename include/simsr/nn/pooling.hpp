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

#include "detail/chunks.hpp"
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
  /// Row within its group of each group's maximum, groups × C (max pooling, last forward).
  const Eigen::Matrix<Index, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& argmax() const { return argmax_; }

  template <exec::HostPolicy Policy = exec::seq_t>
  void forward(Mode, const ConstView<S>& in, Matrix<S>& out, Policy policy = {}) {
    const Index groups = check_rows(in), C = in.cols();
    ensure_shape(out, broadcast_ ? in.rows() : groups, C);
    if (kind_ == PoolKind::max && (argmax_.rows() != groups || argmax_.cols() != C)) argmax_.resize(groups, C);
    ensure_size(pooled_, groups * C);
    each_group(policy, groups, [&](Index g) {
      const Index r0 = g * g_;
      S* p = pooled_.data() + g * C;
      for (Index c = 0; c < C; ++c) {
        if (kind_ == PoolKind::max) {
          Index best = 0;
          for (Index j = 1; j < g_; ++j)
            if (in(r0 + j, c) > in(r0 + best, c)) best = j;
          argmax_(g, c) = best;
          p[c] = in(r0 + best, c);
        } else {
          double s = 0;
          for (Index j = 0; j < g_; ++j) s += double(in(r0 + j, c));
          p[c] = static_cast<S>(s / double(g_));
        }
      }
      if (broadcast_)
        for (Index j = 0; j < g_; ++j) out.row(r0 + j) = ConstMatrixMap<S>(p, 1, C);
      else
        out.row(g) = ConstMatrixMap<S>(p, 1, C);
    });
  }

  template <exec::HostPolicy Policy = exec::seq_t>
  void backward(const ConstView<S>& in, const ConstView<S>&, const ConstView<S>& d_out, Matrix<S>* d_in, Policy policy = {}) {
    const Index groups = check_rows(in), C = in.cols();
    detail::check_shape("nn::GroupPool", "output gradient", d_out, broadcast_ ? in.rows() : groups, C);
    if (kind_ == PoolKind::max && argmax_.rows() != groups) throw ArgumentError("nn::GroupPool: backward needs the forward of the same input first");
    if (!d_in) return;
    ensure_shape(*d_in, in.rows(), C);
    each_group(policy, groups, [&](Index g) {
      const Index r0 = g * g_;
      for (Index c = 0; c < C; ++c) {
        S grad;
        if (broadcast_) {
          grad = S(0);
          for (Index j = 0; j < g_; ++j) grad += d_out(r0 + j, c);
        } else {
          grad = d_out(g, c);
        }
        if (kind_ == PoolKind::max) {
          for (Index j = 0; j < g_; ++j) (*d_in)(r0 + j, c) = S(0);
          (*d_in)(r0 + argmax_(g, c), c) = grad;
        } else {
          const S share = grad / S(g_);
          for (Index j = 0; j < g_; ++j) (*d_in)(r0 + j, c) = share;
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
  template <class Policy, class Body>
  void each_group(Policy policy, Index groups, Body&& body) {
    const Index nc = detail::chunk_count(groups, detail::product_chunks), workers = detail::worker_count(policy, nc);
    detail::for_chunks(policy, groups, nc, workers, [&](Index, Index, Index b, Index e) {
      for (Index g = b; g < e; ++g) body(g);
    });
  }

  PoolKind kind_;
  Index g_;
  bool broadcast_;
  Eigen::Matrix<Index, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> argmax_;
  Vector<S> pooled_;
};

}  // namespace simsr::nn
