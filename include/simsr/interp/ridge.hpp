#pragma once
/// \file
/// The data-driven linear baseline of SPEC §6: ridge regression from LR displacements to the HR
/// residual left by a base interpolator (Embedded by default), fitted on training frames. Every
/// learned method should be judged beside it: where training frames span a low-dimensional linear
/// family (the bunny example: head rotations of one body-frame deformation), a matrix already
/// predicts the HR surface almost exactly, and a network that does not beat it learns nothing a
/// matrix cannot.
///
/// Kernel (dual) form, because 3N and 3M (47k and 107k at the paper's size) dwarf the number of
/// training frames F: with centred training inputs X (F×3N) and residuals Y (F×3M),
///     Δx^H(x) = base(x) + ȳ + Yᵀ (K + λI)⁻¹ X (x − x̄),   K = X Xᵀ  (F×F),
/// so fit stores X, Y and the F×F inverse, and apply costs O(F·(N + M)) per frame.
/// λ is chosen by generalized cross-validation (GCV) over a log grid unless given.
///
///     interp::Ridge<> ridge;                                    // residual over interp::Embedded<>
///     ridge.fit(exec::omp, problem);                            // the base interpolator's fit
///     ridge.train(exec::omp, data::displacements(train, lr.V, hr.V), {});   // λ by GCV
///     ridge.apply(exec::omp, lr_displacement, hr_displacement);

#include <cmath>
#include <limits>
#include <type_traits>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "../core/eigen_threads.hpp"
#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../data/paired_frames.hpp"
#include "concepts.hpp"
#include "embedded.hpp"
#include "problem.hpp"

namespace simsr::interp {

/// What the model is.
struct RidgeOptions {
  /// true: learn the residual over the base interpolator (SPEC §6); false: learn Δx^H itself.
  bool residual = true;
};

/// How train chooses λ.
struct RidgeTrainOptions {
  /// λ of the ridge penalty (in units of K's mean eigenvalue, so it is scale-free); < 0: by GCV.
  double lambda = -1;
  /// GCV grid: λ/mean eigenvalue from 10^lo to 10^hi, `steps` points.
  double gcv_log10_lo = -12, gcv_log10_hi = 2;
  int gcv_steps = 57;
  /// Eigenvalues of the frame kernel K below this fraction of the largest are treated as zero.
  double rank_tolerance = 1e-10;
};

/// What training chose.
struct RidgeTrainInfo {
  Index frames = 0;
  double lambda = 0;          ///< λ used, absolute (K's units)
  double lambda_relative = 0; ///< λ / mean eigenvalue of K
  double gcv = 0;             ///< GCV score at λ (mean squared residual per output, leave-one-out proxy)
  double effective_dof = 0;   ///< trace of the hat matrix
  Index rank = 0;             ///< eigenvalues of K kept (numerical rank of the centred inputs)
};

/// Ridge regression over a base interpolator. `Base` is any interp::Interpolator of the same
/// scalar (default Embedded). Satisfies interp::TrainableInterpolator.
template <class S = Scalar, class Base = Embedded<S>>
class Ridge {
  static_assert(assert_interpolator<Base>());
  static_assert(std::is_same_v<typename Base::scalar_type, S>, "interp::Ridge<S, Base>: Base must interpolate the same scalar type S");

 public:
  using scalar_type = S;
  using train_options = RidgeTrainOptions;
  using Matrix = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  /// fit is the base's fit.
  static constexpr bool needs_neighborhoods = needs_neighborhoods_v<Base>;

  Ridge() = default;
  explicit Ridge(RidgeOptions options, Base base = Base{}) : options_(options), base_(std::move(base)) {}

  /// Fits the base interpolator on the rest shapes; train() must follow before apply().
  template <exec::HostPolicy Policy>
  void fit(Policy policy, UpsamplingProblem<S>& problem) {
    base_.fit(policy, problem);
    n_ = problem.num_lr();
    m_ = problem.num_hr();
    trained_ = false;
  }

  /// Trains on F paired frames of displacements from the fitted rest shapes (data::displacements).
  template <exec::HostPolicy Policy>
  void train(Policy policy, const data::PairedFrames<S>& frames_in, const RidgeTrainOptions& train_options) {
    if (n_ == 0 || m_ == 0) throw ArgumentError("Ridge::train before fit");
    const Index frames = frames_in.num_frames();
    if (frames < 2) throw ArgumentError("Ridge::train needs at least 2 frames, got " + std::to_string(frames));
    if (frames_in.num_lr() != n_) throw ShapeError("Ridge::train: LR displacements", {frames, n_, 3}, {frames, frames_in.num_lr(), 3});
    if (frames_in.num_hr() != m_) throw ShapeError("Ridge::train: HR displacements", {frames, m_, 3}, {frames, frames_in.num_hr(), 3});
    const auto& options = train_options;
    const Index dout = 3 * m_;
    X_ = frames_in.lowres;
    Y_ = frames_in.highres;
    if (!X_.allFinite() || !Y_.allFinite()) throw ArgumentError("Ridge::train: non-finite displacements");
    if (options_.residual) {
      Points<S> in(n_, 3), out(m_, 3);
      for (Index f = 0; f < frames; ++f) {  // residual over the base interpolator
        in = frames_in.lr(f);
        base_.apply(policy, in, out);
        Y_.row(f) -= Eigen::Map<const Eigen::Matrix<S, 1, Eigen::Dynamic>>(out.data(), dout);
      }
    }
    x_mean_ = X_.colwise().mean();
    y_mean_ = Y_.colwise().mean();
    X_.rowwise() -= x_mean_;
    Y_.rowwise() -= y_mean_;

    // Eigen's products and eigen-solver below would start threads of their own (any policy).
    const EigenSingleThreaded eigen_serial;
    // K = X Xᵀ in double: its eigenvalues span many decades on near-linear data.
    const Eigen::MatrixXd Xd = X_.template cast<double>();
    const Eigen::MatrixXd K = Xd * Xd.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(K);
    if (eig.info() != Eigen::Success) throw ConvergenceError("Ridge: eigen-decomposition of the frame kernel", 0, 0);
    // Eigenvalues below rank_tolerance·s_max are rounding noise of K's null space (F > rank X,
    // e.g. more frames than input dimensions): (K+λI)⁻¹ would amplify them by 1/λ, so their
    // eigenvectors are dropped from G (exact: X(x − x̄) has no component there).
    const double s_max = std::max(eig.eigenvalues().maxCoeff(), 0.0);
    Eigen::VectorXd s = eig.eigenvalues();
    Eigen::VectorXd keep = (s.array() > options.rank_tolerance * s_max).template cast<double>();
    s = s.cwiseProduct(keep);
    const double mean_eig = s.sum() / double(frames);
    if (!(mean_eig > 0)) throw ArgumentError("Ridge::train: all LR training displacements are identical");
    const Eigen::MatrixXd UtY = eig.eigenvectors().transpose() * Y_.template cast<double>();
    const Eigen::VectorXd energy = UtY.rowwise().squaredNorm();  // ‖(UᵀY)_i‖² per eigenvector

    // GCV(λ) = F·‖(I−H)Y‖² / (F − tr H)², H = K(K+λI)⁻¹, all in the eigenbasis.
    auto gcv = [&](double lam, double& dof) {
      double rss = 0;
      dof = 0;
      for (Index i = 0; i < frames; ++i) {
        const double shrink = keep[i] > 0 ? lam / (s[i] + lam) : 1.0;
        rss += shrink * shrink * energy[i];
        dof += keep[i] > 0 ? s[i] / (s[i] + lam) : 0.0;
      }
      const double denom = double(frames) - dof;
      return denom > 0 ? double(frames) * rss / (denom * denom * double(dout)) : std::numeric_limits<double>::infinity();
    };
    double lam = 0, best = std::numeric_limits<double>::infinity(), dof = 0;
    if (options.lambda >= 0) {
      lam = options.lambda * mean_eig;
      best = gcv(lam, dof);
    } else {
      for (int k = 0; k < options.gcv_steps; ++k) {
        const double t = options.gcv_log10_lo + (options.gcv_log10_hi - options.gcv_log10_lo) * k / std::max(1, options.gcv_steps - 1);
        double d = 0;
        const double g = gcv(std::pow(10.0, t) * mean_eig, d);
        if (g < best) best = g, lam = std::pow(10.0, t) * mean_eig, dof = d;
      }
    }
    if (!(lam > 0)) throw ArgumentError("Ridge::train: λ must be positive (got " + std::to_string(lam) + ")");
    const Eigen::VectorXd inv = (s.array() + lam).inverse().matrix().cwiseProduct(keep);
    G_ = (eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose()).template cast<S>();
    Yt_ = Y_.transpose();  // 3M×F: apply's output loop reads one contiguous row per output
    Y_.resize(0, 0);
    info_ = {frames, lam, lam / mean_eig, best, dof, Index(keep.sum())};
    kx_.resize(frames);
    alpha_.resize(frames);
    trained_ = true;
  }

  /// Δx^H = base(x) + ȳ + Yᵀ G X (x − x̄) for one frame (N×3 → M×3). Not thread-safe per object
  /// (F-sized scratch vectors are reused; nothing is allocated).
  template <exec::HostPolicy Policy>
  void apply(Policy policy, const ConstPointsRef<S>& lr_displacement, PointsRef<S> hr_displacement) const {
    if (!trained_) throw ArgumentError("Ridge::apply before train");
    if (lr_displacement.rows() != n_) throw ShapeError("Ridge::apply: LR displacement", {n_, 3}, {lr_displacement.rows(), 3});
    if (hr_displacement.rows() != m_) throw ShapeError("Ridge::apply: HR displacement", {m_, 3}, {hr_displacement.rows(), 3});
    const Index frames = X_.rows(), din = 3 * n_, dout = 3 * m_;
    const S* x = lr_displacement.data();
    exec::parallel_for(policy, frames, [&](Index f) {
      S acc = 0;
      for (Index i = 0; i < din; ++i) acc += X_(f, i) * (x[i] - x_mean_[i]);
      kx_[f] = acc;
    });
    alpha_.noalias() = G_ * kx_;
    if (options_.residual)
      base_.apply(policy, lr_displacement, hr_displacement);
    else
      hr_displacement.setZero();
    S* y = hr_displacement.data();
    exec::parallel_for(policy, dout, [&](Index o) {
      S acc = y_mean_[o];
      for (Index f = 0; f < frames; ++f) acc += Yt_(o, f) * alpha_[f];
      y[o] += acc;
    });
  }

  Index num_lr() const { return n_; }
  Index num_hr() const { return m_; }
  const RidgeTrainInfo& info() const { return info_; }
  const Base& base() const { return base_; }

 private:
  RidgeOptions options_;
  Base base_;
  Index n_ = 0, m_ = 0;
  bool trained_ = false;
  Matrix X_, Y_, Yt_, G_;
  Eigen::Matrix<S, 1, Eigen::Dynamic> x_mean_, y_mean_;
  mutable Eigen::Matrix<S, Eigen::Dynamic, 1> kx_, alpha_;
  RidgeTrainInfo info_;
};

static_assert(assert_trainable_interpolator<Ridge<double>>());
static_assert(assert_trainable_interpolator<Ridge<float>>());

}  // namespace simsr::interp
