#pragma once
/// \file
/// Concatenation of channel blocks (columns) and its backward split (SPEC §7: h⁰ = [Δx, PE],
/// the edge features cat(h_j − h_i, h_i), `fc_out` on cat(h, g, max, mean), z = [h⁰, h¹, h²]).
///
///     nn::Concat<float> cat({C, C, C, C});
///     cat.forward(exec::omp, {h, g, gmax, gmean}, x);           // rows × 4C
///     cat.backward(exec::omp, dx, {&dh, &dg, nullptr, nullptr}); // split; null parts skipped

#include <initializer_list>
#include <numeric>
#include <vector>

#include "tensor.hpp"

namespace simsr::nn {

/// Column concatenation of inputs with fixed channel widths and equal row counts. Not an
/// nn::Layer (several inputs), but the same conventions: out resized only on a shape change,
/// seq and omp identical (copies), ShapeError naming the offending part.
template <class S = float>
class Concat {
 public:
  using scalar_type = S;

  explicit Concat(std::vector<Index> widths) : widths_(std::move(widths)), offsets_(widths_.size() + 1, 0) {
    if (widths_.empty()) throw ArgumentError("nn::Concat: needs at least one part");
    for (std::size_t i = 0; i < widths_.size(); ++i) {
      if (widths_[i] < 1) throw ArgumentError("nn::Concat: part " + std::to_string(i) + " has width < 1");
      offsets_[i + 1] = offsets_[i] + widths_[i];
    }
  }

  Index parts() const { return Index(widths_.size()); }
  Index width(Index i) const { return widths_[std::size_t(i)]; }
  /// First column of part i in the output.
  Index offset(Index i) const { return offsets_[std::size_t(i)]; }
  Index out_features() const { return offsets_.back(); }

  /// out = [in₀, in₁, …] (rows × Σ widths).
  template <exec::HostPolicy Policy>
  void forward(Policy policy, std::initializer_list<ConstView<S>> ins, Matrix<S>& out) const {
    forward_parts(policy, ins.size(), [&](std::size_t i) -> const ConstView<S>& { return ins.begin()[i]; }, out);
  }

  /// The same with the parts given by part(i) (i < n), for a number of parts known at run time
  /// (FeatureEmbedding's z = [h⁰, h¹, …]); nothing is allocated.
  template <exec::HostPolicy Policy, class Part>
  void forward_parts(Policy policy, std::size_t n, Part&& part, Matrix<S>& out) const {
    check_count(n);
    const Index R = part(0).rows();
    for (std::size_t i = 0; i < n; ++i) detail::check_shape("nn::Concat", part_name(i).c_str(), part(i), R, widths_[i]);
    ensure_shape(out, R, out_features());
    const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, R, nc, workers, [&](Index, Index, Index b, Index e) {
      for (std::size_t p = 0; p < n; ++p) out.block(b, offsets_[p], e - b, widths_[p]) = part(p).middleRows(b, e - b);
    });
  }

  /// Splits d_out into the parts' gradients: d_ins[i] = columns of part i (overwritten, or added
  /// with `accumulate`, where d_ins[i] must already be rows × width(i)); null entries are skipped.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& d_out, std::initializer_list<Matrix<S>*> d_ins, bool accumulate = false) const {
    backward_parts(policy, d_out, d_ins.size(), [&](std::size_t i) { return d_ins.begin()[i]; }, accumulate);
  }

  /// The same with the gradients given by grad(i) (i < n; null: skipped).
  template <exec::HostPolicy Policy, class Grad>
  void backward_parts(Policy policy, const ConstView<S>& d_out, std::size_t n, Grad&& grad, bool accumulate = false) const {
    check_count(n);
    detail::check_shape("nn::Concat", "output gradient", d_out, -1, out_features());
    const Index R = d_out.rows();
    for (std::size_t i = 0; i < n; ++i) {
      if (Matrix<S>* d = grad(i)) {
        if (accumulate)
          detail::check_shape("nn::Concat", (part_name(i) + " gradient").c_str(), *d, R, widths_[i]);
        else
          ensure_shape(*d, R, widths_[i]);
      }
    }
    const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, R, nc, workers, [&](Index, Index, Index b, Index e) {
      for (std::size_t p = 0; p < n; ++p) {
        Matrix<S>* d = grad(p);
        if (!d) continue;
        if (accumulate)
          d->middleRows(b, e - b) += d_out.block(b, offsets_[p], e - b, widths_[p]);
        else
          d->middleRows(b, e - b) = d_out.block(b, offsets_[p], e - b, widths_[p]);
      }
    });
  }

 private:
  void check_count(std::size_t n) const {
    if (n != widths_.size())
      throw ArgumentError("nn::Concat: expected " + std::to_string(widths_.size()) + " parts, got " + std::to_string(n));
  }
  static std::string part_name(std::size_t i) { return "part " + std::to_string(i); }

  std::vector<Index> widths_;
  std::vector<Index> offsets_;
};

}  // namespace simsr::nn
