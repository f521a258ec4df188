#pragma once
/// \file
/// Activation matrices of the network, the train/eval mode, shape checks and the random source.
///
/// Layout: activations are row-major matrices laid out **points × channels**. A batch of B point
/// clouds of N points each with C channels is one (B·N)×C matrix whose rows are point-major within
/// a batch item: row b·N + n holds point n of item b. PyTorch's Conv1d input x[b, c, n] (B×C×N) is
/// our row b·N + n, column c, i.e. `x.permute(0, 2, 1).reshape(B*N, C)`; a Conv2d input
/// x[b, c, n, k] (B×C×N×K, the edge features of §3.1) is row (b·N + n)·K + k. With this layout a
/// 1×1 convolution is one product rows × Wᵀ, per-channel statistics (BatchNorm) are column
/// reductions, and a point's channels are contiguous (concatenation = column blocks).

#include <cstdint>
#include <random>
#include <string>
#include <string_view>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"

namespace simsr::nn {

/// Activations, gradients and weights: row-major, points × channels (see the file comment).
template <class S = float>
using Matrix = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Read-only input of a layer: a whole Matrix or a column block of one (no copy in either case).
template <class S = float>
using ConstView = Eigen::Ref<const Matrix<S>, 0, Eigen::OuterStride<>>;

template <class S = float>
using Vector = Eigen::Matrix<S, Eigen::Dynamic, 1>;

template <class S = float>
using MatrixMap = Eigen::Map<Matrix<S>>;
template <class S = float>
using VectorMap = Eigen::Map<Vector<S>>;
template <class S = float>
using ConstMatrixMap = Eigen::Map<const Matrix<S>>;
template <class S = float>
using ConstVectorMap = Eigen::Map<const Vector<S>>;

/// train: BatchNorm normalizes with batch statistics and updates its running averages;
/// eval: it uses the running averages (PyTorch's module.train() / module.eval()).
enum class Mode { train, eval };

/// Row chunks of the layers, scheduled by exec::chunk_count / exec::for_chunks: products (GEMM
/// blocks, elementwise maps) over product_chunks, reductions over rows (weight gradients,
/// BatchNorm statistics) over reduction_chunks, partial sums merged in chunk order. Fixed numbers
/// (not the thread count), so exec::seq and exec::omp give the same bits.
inline constexpr Index product_chunks = 64;
inline constexpr Index reduction_chunks = 16;

/// The random source of initializers: 64-bit Mersenne twister, the same stream on every platform.
using Rng = std::mt19937_64;

/// Uniform draw in [lo, hi) from the top 53 bits of one `rng()` call (std::uniform_real_distribution
/// is implementation-defined; this is not, so a seed gives the same weights everywhere).
inline double uniform(Rng& rng, double lo, double hi) {
  const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;
  return lo + (hi - lo) * u;
}

/// Gives `m` the shape rows×cols, reallocating only when the shape changes.
template <class S>
void ensure_shape(Matrix<S>& m, Index rows, Index cols) {
  if (m.rows() != rows || m.cols() != cols) m.resize(rows, cols);
}
template <class S>
void ensure_size(Vector<S>& v, Index n) {
  if (v.size() != n) v.resize(n);
}

namespace detail {

/// ShapeError "`layer`: `what`: expected shape (rows, cols), got (…)" unless m is rows×cols
/// (a negative expected size matches any size).
/// (string_view: no string is built unless it throws.)
template <class M>
void check_shape(std::string_view layer, std::string_view what, const M& m, Index rows, Index cols) {
  if ((rows >= 0 && m.rows() != rows) || (cols >= 0 && m.cols() != cols))
    throw ShapeError(std::string(layer) + ": " + std::string(what), {rows, cols}, {m.rows(), m.cols()});
}

}  // namespace detail
}  // namespace simsr::nn
