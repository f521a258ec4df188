#pragma once
/// \file
/// Learned::apply as launches of device-callable bodies over one memory space (issue #17 item 5):
/// the LR displacements normalized as Learned does (positions in double, then float), the
/// network's inference (nn::InferenceNet), the prediction scaled back to mesh units, with
/// Learned::apply's checks (an input beyond the network's float range or not finite:
/// ArgumentError; a non-finite prediction: NumericalError, naming the vertex).
/// `LearnedInference<Net, HostBuffer>` runs under exec::seq / exec::omp (the CPU tests check it
/// against Learned::apply), `DeviceLearned` (nvcc only, `to_device(policy, learned)`) the same
/// launches under exec::cuda.
///
///     interp::Learned<> learned;  learned.fit(…); learned.train(…);         // or from_model_file
///     auto d = interp::to_device(exec::omp, learned);                        // DeviceLearned<>
///     d.apply(exec::cuda, lr_span, hr_span);   // MatrixSpan<const double> N×3, MatrixSpan<double> M×3, device memory

#include <limits>
#include <string>

#include "../core/error.hpp"
#include "../core/host_buffer.hpp"
#include "../core/parallel.hpp"
#include "../nn/inference_net.hpp"
#include "learned.hpp"

namespace simsr::interp {

namespace detail {
/// Learned's input rule, entry k = r·3 + c: x = rest + d in double; the network's input
/// ((float(x) − μ)/σ − lr0)·scale in S (nn::normalized_displacements' order of operations).
template <class S>
struct NormalizeLearnedInput {
  MatrixSpan<const double> rest, d;  ///< N×3 each
  const S* rest_normalized;          ///< N×3, contiguous
  double mean, std_dev;
  S scale;
  bool scaled;
  MatrixSpan<S> out;  ///< N×3

  SIMSR_HOST_DEVICE double position(Index k) const { return rest(k / 3, k % 3) + d(k / 3, k % 3); }
  /// Not finite, or beyond S's range once normalized (Learned::apply's ArgumentError).
  SIMSR_HOST_DEVICE bool refused(Index k) const {
    const double x = position(k);
    return !std::isfinite(x) || std::abs((x - mean) / std_dev) > double(std::numeric_limits<S>::max());
  }
  SIMSR_HOST_DEVICE void operator()(Index k) const {
    const S mu = static_cast<S>(mean), sigma = static_cast<S>(std_dev);
    S v = (static_cast<S>(position(k)) - mu) / sigma - rest_normalized[k];
    if (scaled) v *= scale;
    out(k / 3, k % 3) = v;
  }
};

/// hr = double(pred)·σ_unit, entry k = r·3 + c.
template <class S>
struct ScaleLearnedOutput {
  MatrixSpan<const S> pred;
  double unit;
  MatrixSpan<double> hr;
  SIMSR_HOST_DEVICE double value(Index k) const { return double(pred(k / 3, k % 3)) * unit; }
  SIMSR_HOST_DEVICE void operator()(Index k) const { hr(k / 3, k % 3) = value(k); }
};

/// The first index k < n with `bad(k)`, or n (a reduction: the order of the combination does not matter).
struct FirstIndex {
  SIMSR_HOST_DEVICE Index operator()(Index a, Index b) const { return a < b ? a : b; }
};
template <class S>
struct FirstRefusedInput {
  NormalizeLearnedInput<S> body;
  Index n;
  SIMSR_HOST_DEVICE Index operator()(Index k) const { return body.refused(k) ? k : n; }
};
template <class S>
struct FirstNonFiniteOutput {
  ScaleLearnedOutput<S> body;
  Index n;
  SIMSR_HOST_DEVICE Index operator()(Index k) const { return std::isfinite(body.value(k)) ? n : k; }
};
}  // namespace detail

template <class Net, template <class> class Memory>
class LearnedInference {
 public:
  using S = typename Net::scalar_type;

  /// Copies a fitted (trained or loaded) Learned's normalization and network (its upsampling
  /// weights prepared under `policy` when not yet). ArgumentError before fit.
  template <exec::HostPolicy Policy>
  LearnedInference(Policy policy, Learned<Net>& learned)
      : net_(policy, checked_network(learned)),
        rest_(Span<const double>{learned.model().geometry.lr_rest.data(), learned.model().geometry.lr_rest.size()}),
        mean_(learned.config().norm_mean),
        std_(learned.config().norm_std),
        scale_(learned.config().displacement_scale),
        unit_(learned.config().displacement_unit()),
        n_(learned.num_lr()),
        m_(learned.num_hr()) {
    const nn::Matrix<S> lr0 = nn::normalize_positions<S>(learned.model().geometry.lr_rest, mean_, std_);
    rest_normalized_ = Memory<S>(Span<const S>{lr0.data(), lr0.size()});
    ldx_.resize(3 * n_);
    pred_.resize(3 * m_);
  }

  Index num_lr() const { return n_; }
  Index num_hr() const { return m_; }

  /// hr_displacement (M×3) from lr_displacement (N×3), mesh units, both in this instance's memory
  /// space: Learned::apply's values up to the network's rounding (nn::InferenceNet). ShapeError
  /// for other shapes; ArgumentError for an input Learned refuses; NumericalError for a
  /// non-finite prediction.
  template <class Policy>
  void apply(Policy policy, MatrixSpan<const double> lr_displacement, MatrixSpan<double> hr_displacement) {
    static_assert(PolicyFor<Policy, Memory>,
                  "interp::LearnedInference runs under the policy of its memory: exec::seq or exec::omp for HostBuffer, exec::cuda for DeviceBuffer");
    if (lr_displacement.rows != n_ || lr_displacement.cols != 3)
      throw ShapeError("LearnedInference::apply: LR displacement", {n_, 3}, {lr_displacement.rows, lr_displacement.cols});
    if (hr_displacement.rows != m_ || hr_displacement.cols != 3)
      throw ShapeError("LearnedInference::apply: HR displacement", {m_, 3}, {hr_displacement.rows, hr_displacement.cols});
    const MatrixSpan<S> ldx{ldx_.span().data, n_, 3, 3};
    const detail::NormalizeLearnedInput<S> normalize{{rest_.span().data, n_, 3, 3}, lr_displacement, rest_normalized_.span().data, mean_, std_,
                                                     static_cast<S>(scale_), scale_ != 1.0, ldx};
    const Index in = 3 * n_;
    if (const Index k = exec::parallel_reduce(policy, in, in, detail::FirstRefusedInput<S>{normalize, in}, detail::FirstIndex{}); k < in) {
      const double x = rest_.value_at(k), d = value_at(lr_displacement, k);
      throw ArgumentError("LearnedInference::apply: LR displacement of vertex " + std::to_string(k / 3) + " is " + std::to_string(d) +
                          (std::isfinite(x + d) ? ": beyond the network's float range after normalization" : ": not finite"));
    }
    exec::parallel_for(policy, in, normalize);
    const MatrixSpan<S> pred{pred_.span().data, m_, 3, 3};
    net_.infer(policy, MatrixSpan<const S>{ldx.data, n_, 3, 3}, pred);
    const detail::ScaleLearnedOutput<S> scale{{pred.data, m_, 3, 3}, unit_, hr_displacement};
    const Index out = 3 * m_;
    if (const Index k = exec::parallel_reduce(policy, out, out, detail::FirstNonFiniteOutput<S>{scale, out}, detail::FirstIndex{}); k < out)
      throw NumericalError("LearnedInference::apply", "the prediction of HR vertex " + std::to_string(k / 3), -1, double(pred_.value_at(k)) * unit_);
    exec::parallel_for(policy, out, scale);
  }

  /// apply on host arrays (copies in and out: the device instance's transfers). Both arrays are
  /// contiguous rows of 3 (ConstPointsRef / PointsRef fix the row stride at 3; Eigen packs any
  /// other layout of lr into a temporary before the call), so each is one copy. Allocates nothing
  /// once warm.
  template <class Policy>
  void apply(Policy policy, const ConstPointsRef<double>& lr_displacement, PointsRef<double> hr_displacement) {
    if (lr_displacement.rows() != n_) throw ShapeError("LearnedInference::apply: LR displacement", {n_, 3}, {lr_displacement.rows(), 3});
    if (hr_displacement.rows() != m_) throw ShapeError("LearnedInference::apply: HR displacement", {m_, 3}, {hr_displacement.rows(), 3});
    lr_in_.resize(3 * n_);
    lr_in_.copy_from(Span<const double>{lr_displacement.data(), 3 * n_});
    hr_out_.resize(3 * m_);
    apply(policy, MatrixSpan<const double>{lr_in_.span().data, n_, 3, 3}, MatrixSpan<double>{hr_out_.span().data, m_, 3, 3});
    hr_out_.copy_to(Span<double>{hr_displacement.data(), 3 * m_});
  }

 private:
  /// Entry k = r·3 + c of a caller's array in this memory space, copied to the host (for a message).
  static double value_at(MatrixSpan<const double> a, Index k) {
    const double* p = a.data + (k / 3) * a.stride + k % 3;
    if constexpr (device_memory<Memory>) {
#if defined(__CUDACC__)
      double v = std::numeric_limits<double>::quiet_NaN();
      (void)cudaMemcpy(&v, p, sizeof(double), cudaMemcpyDeviceToHost);  // for the message only
      return v;
#endif
    } else {
      return *p;
    }
  }

  static Net& checked_network(Learned<Net>& learned) {
    if (learned.num_lr() == 0) throw ArgumentError("LearnedInference: the Learned interpolator is not fitted");
    return learned.network();
  }

  nn::InferenceNet<S, Memory> net_;
  Memory<double> rest_;
  Memory<S> rest_normalized_;
  double mean_, std_, scale_, unit_;
  Index n_, m_;
  Memory<S> ldx_, pred_;
  Memory<double> lr_in_, hr_out_;  ///< apply on host arrays: the transfers' buffers
};

/// The host instance (the device path's launches under exec::seq / exec::omp).
template <class Net = nn::SuperResolutionNet<float>>
using HostLearned = LearnedInference<Net, HostBuffer>;

#if defined(__CUDACC__)
/// The device instance (nvcc only).
template <class Net = nn::SuperResolutionNet<float>>
using DeviceLearned = LearnedInference<Net, DeviceBuffer>;

/// A fitted Learned's device twin.
template <exec::HostPolicy Policy, class Net>
DeviceLearned<Net> to_device(Policy policy, Learned<Net>& learned) {
  return DeviceLearned<Net>(policy, learned);
}
#endif

}  // namespace simsr::interp
