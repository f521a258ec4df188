#pragma once
/// \file
/// Fixed sinusoidal positional encoding of the vertex index, concatenated to the input:
/// h⁰ = [Δx, PE(i)] (SPEC §7, the reference's `PosEmb`, D = 32). Not trained.
///
///     nn::PositionalEncoding<float> pe(num_lr_vertices);   // D = 32
///     pe.forward(exec::omp, nn::Mode::train, dx, h0);      // (B·N)×3 → (B·N)×35

#include <cmath>

#include "layer.hpp"

namespace simsr::nn {

/// PE(i)_{2m} = sin(i / 10000^{2m/D}), PE(i)_{2m+1} = cos(i / 10000^{2m/D}), i = vertex index
/// (the row within its batch item: row r is vertex r mod N). The table is computed in S the way
/// the reference computes it in float32 (exponent 2m/D, then the power, the quotient, sin/cos),
/// so it agrees with PyTorch's table to the last bit or so.
template <class S = float>
class PositionalEncoding {
 public:
  using scalar_type = S;

  /// N vertices per batch item, D encoding channels (even, ≥ 2).
  explicit PositionalEncoding(Index num_points, Index dim = 32) : n_(num_points), d_(dim) {
    if (num_points < 1) throw ArgumentError("nn::PositionalEncoding: num_points must be >= 1");
    if (dim < 2 || dim % 2) throw ArgumentError("nn::PositionalEncoding: dim must be even and >= 2, got " + std::to_string(dim));
    table_.resize(n_, d_);
    for (Index m2 = 0; m2 < d_; m2 += 2) {
      const S denom = std::pow(S(10000), S(m2) / S(d_));
      for (Index i = 0; i < n_; ++i) {
        const S a = S(i) / denom;
        table_(i, m2) = std::sin(a);
        table_(i, m2 + 1) = std::cos(a);
      }
    }
  }

  Index num_points() const { return n_; }
  Index dim() const { return d_; }
  Index out_features(Index in_cols) const { return in_cols + d_; }
  /// N×D table.
  const Matrix<S>& table() const { return table_; }

  /// out = [in, PE(row mod N)]: (B·N)×C → (B·N)×(C+D). ShapeError when rows are not a multiple of N.
  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode, const ConstView<S>& in, Matrix<S>& out) {
    check_rows(in);
    const Index R = in.rows(), C = in.cols();
    ensure_shape(out, R, C + d_);
    const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, R, nc, workers, [&](Index, Index, Index b, Index e) {
      for (Index r = b; r < e; ++r) {
        out.row(r).head(C) = in.row(r);
        out.row(r).tail(d_) = table_.row(r % n_);
      }
    });
  }
  /// d_in = the first C columns of d_out (the encoding has no gradient).
  template <exec::HostPolicy Policy>
  void backward(Policy, const ConstView<S>& in, const ConstView<S>&, const ConstView<S>& d_out, Matrix<S>* d_in) {
    detail::check_shape("nn::PositionalEncoding", "output gradient", d_out, in.rows(), in.cols() + d_);
    if (!d_in) return;
    ensure_shape(*d_in, in.rows(), in.cols());
    *d_in = d_out.leftCols(in.cols());
  }

 private:
  void check_rows(const ConstView<S>& in) const {
    if (in.rows() % n_) throw ShapeError("nn::PositionalEncoding: input rows (batch × " + std::to_string(n_) + " points)", {-1, in.cols()}, {in.rows(), in.cols()});
  }
  Index n_, d_;
  Matrix<S> table_;
};
static_assert(assert_layer<PositionalEncoding<float>>());

}  // namespace simsr::nn
