#pragma once
/// \file
/// A learned local linear upsampler: each HR vertex's displacement as a linear map of the
/// displacements of its k §3.2 upsampling neighbours (the LR vertices the network's coordinate
/// upsampling reads, Eq. 1),
///     Δx^H_i = Σ_{j ∈ N(i)} W_ij Δx^L_j,    W_ij ∈ R^{3×3},
/// fitted per HR vertex by ridge regression on the training frames. It is the linear core of the
/// network's upsampling (z^H_i = Σ_j w_ij z_j, Eq. 3) with the weights learned from frames instead
/// of from rest coordinates, and full 3×3 blocks, so the local rotation of the flesh around a
/// vertex carries over (scalar weights, one per neighbour, do no better than global ridge on the
/// face). Against interp::Ridge (one global map from every LR vertex to every HR vertex) it has
/// 9k parameters per vertex instead of a 3N-wide row: it cannot learn that an eyebrow moves when
/// the mouth does, which is exactly why it carries to performances whose expressions combine
/// muscles differently from the training frames' (README: "The network on the face").
///
/// No intercept: a zero LR displacement gives a zero HR displacement, as for every interpolator.
/// λ is relative to each vertex's mean Gram eigenvalue, tr(AᵀA)/3k, and chosen on a log grid by
/// cross-validation: leave one sequence out when the frames name two or more sequences (data's
/// `sequence`: a held-out performance is what the method meets), else `folds` contiguous blocks.
/// A vertex whose neighbours never move in the training frames gets W = 0.
///
///     interp::LocalLinear<> ll;                                   // k = 20
///     ll.fit(exec::omp, problem);                                 // reads problem.neighborhoods
///     ll.train(exec::omp, data::displacements(train, lr.V, hr.V), {});   // λ by cross-validation
///     ll.apply(exec::omp, lr_displacement, hr_displacement);
///     auto map = ll.linear_map();   // 3M×3N sparse: the network's residual base (NetworkConfig)

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <nlohmann/json.hpp>

#include "../core/eigen_threads.hpp"
#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../data/paired_frames.hpp"
#include "concepts.hpp"
#include "detail/kernel.hpp"
#include "problem.hpp"

namespace simsr::interp {

/// What the model is.
struct LocalLinearOptions {
  Index k = 20;  ///< upsampling neighbours per HR vertex (the problem's §3.2 neighbourhoods)
};

/// How train chooses λ.
struct LocalLinearTrainOptions {
  /// λ relative to each vertex's mean Gram eigenvalue; < 0: by cross-validation on the grid.
  double lambda = -1;
  double log10_lo = -9, log10_hi = -1;  ///< the grid: 10^lo … 10^hi
  int steps = 9;
  /// Contiguous blocks of frames, when the frames name fewer than two sequences.
  Index folds = 5;
};

/// What training chose.
struct LocalLinearTrainInfo {
  Index frames = 0;
  Index folds = 0;             ///< 0 when λ was given
  bool by_sequence = false;    ///< folds are the frames' sequences
  double lambda_relative = 0;  ///< λ used
  /// Cross-validated root mean squared error per HR coordinate at each grid λ (empty when λ was given).
  std::vector<double> grid_lambda, grid_rmse;
  Index still_vertices = 0;    ///< HR vertices whose neighbours never move in training (W = 0)

  /// For reports (simsr train, the demo's network stage).
  nlohmann::ordered_json to_json() const {
    return {{"lambda_relative", lambda_relative}, {"folds", folds}, {"folds_by_sequence", by_sequence}, {"still_vertices", still_vertices}};
  }
};

/// The local linear upsampler (S = double or float). Satisfies interp::TrainableInterpolator.
namespace detail {
/// LocalLinear::apply's body, HR vertex v: Δx^H_v = Σ_k W_vk Δx^L_{i(v,k)}, each 3×3 W_vk applied
/// column by column, k ascending. SIMSR_HOST_DEVICE over raw arrays: apply runs it under seq and
/// omp, DeviceLocalLinear under exec::cuda.
template <class S>
struct LocalLinearRow {
  const VIndex* indices;  ///< M×K row-major
  const S* maps;          ///< M × 9K: row v, entry (3k + a)·3 + c
  Index K;
  MatrixSpan<const S> lr;  ///< N×3
  MatrixSpan<S> hr;        ///< M×3

  SIMSR_HOST_DEVICE void operator()(Index v) const {
    S out[3] = {0, 0, 0};
    const S* Wv = maps + v * 9 * K;
    for (Index k = 0; k < K; ++k) {
      const Index j = indices[v * K + k];
      for (Index a = 0; a < 3; ++a) {
        const S x = lr(j, a);
        for (Index c = 0; c < 3; ++c) out[c] += x * Wv[3 * (3 * k + a) + c];
      }
    }
    for (Index c = 0; c < 3; ++c) hr(v, c) = out[c];
  }
};
}  // namespace detail

template <class S = Scalar>
class LocalLinear {
 public:
  using scalar_type = S;
  using train_options = LocalLinearTrainOptions;
  static constexpr bool needs_neighborhoods = true;

  LocalLinear() = default;
  explicit LocalLinear(LocalLinearOptions options) : options_(options) {
    if (options_.k < 1) throw ArgumentError("LocalLinear: k = " + std::to_string(options_.k) + " must be >= 1");
  }

  /// Stores the first k neighbours of each HR vertex (problem.neighborhoods must be present).
  template <exec::HostPolicy Policy>
  void fit(Policy, UpsamplingProblem<S>& problem) {
    const auto& nb = detail::neighborhoods_for(problem, options_.k, "LocalLinear");
    idx_ = nb.indices.leftCols(options_.k);
    n_ = problem.num_lr();
    m_ = problem.num_hr();
    trained_ = false;
  }

  /// Fits every vertex's map on F paired frames of displacements (data::displacements).
  template <exec::HostPolicy Policy>
  void train(Policy policy, const data::PairedFrames<S>& frames, const LocalLinearTrainOptions& options) {
    if (n_ == 0) throw ArgumentError("LocalLinear::train before fit");
    const Index F = frames.num_frames();
    if (F < 2) throw ArgumentError("LocalLinear::train needs at least 2 frames, got " + std::to_string(F));
    if (frames.num_lr() != n_ || frames.num_hr() != m_)
      throw ShapeError("LocalLinear::train: frames (N, M)", {n_, m_}, {frames.num_lr(), frames.num_hr()});
    if (!frames.lowres.allFinite() || !frames.highres.allFinite()) throw ArgumentError("LocalLinear::train: non-finite displacements");
    if (!(options.log10_lo <= options.log10_hi) || options.steps < 1 || !std::isfinite(options.log10_lo) || !std::isfinite(options.log10_hi))
      throw ArgumentError("LocalLinear::train: the λ grid needs log10_lo <= log10_hi (finite) and steps >= 1");
    if (!std::isfinite(options.lambda)) throw ArgumentError("LocalLinear::train: λ is not finite");
    const EigenSingleThreaded eigen_serial;  // small products per vertex, inside our own parallel loop
    const Index D = 3 * options_.k;
    info_ = {};
    info_.frames = F;
    double lambda = options.lambda;
    if (lambda < 0) {
      const std::vector<Index> fold = assign_folds(frames, options.folds, info_.by_sequence);
      const Index nf = *std::max_element(fold.begin(), fold.end()) + 1;
      info_.folds = nf;
      std::vector<double> grid(std::size_t(options.steps));
      for (int s = 0; s < options.steps; ++s)
        grid[std::size_t(s)] = std::pow(10.0, options.steps == 1 ? options.log10_lo : options.log10_lo + (options.log10_hi - options.log10_lo) * s / (options.steps - 1));
      // held-out squared error of every vertex at every λ (summed over folds), reduced in order
      Eigen::MatrixXd score(m_, options.steps);
      exec::parallel_for(policy, m_, [&](Index v) {
        VertexSystem sys(*this, frames, v, D, nf, fold);
        for (int s = 0; s < options.steps; ++s) score(v, s) = sys.held_out_error(grid[std::size_t(s)]);
      });
      Eigen::Index best = 0;
      const Eigen::VectorXd total = score.colwise().sum();
      total.minCoeff(&best);
      lambda = grid[std::size_t(best)];
      info_.grid_lambda = grid;
      for (Index s = 0; s < options.steps; ++s) info_.grid_rmse.push_back(std::sqrt(total[s] / double(3 * m_ * F)));
    }
    info_.lambda_relative = lambda;
    W_.resize(m_, D * 3);
    std::vector<char> still(std::size_t(m_), 0);
    const std::vector<Index> one_fold(std::size_t(F), 0);
    exec::parallel_for(policy, m_, [&](Index v) {
      VertexSystem sys(*this, frames, v, D, 1, one_fold);
      const Eigen::MatrixXd Wv = sys.solve(sys.G_total, sys.B_total, lambda);
      still[std::size_t(v)] = sys.G_total.trace() > 0 ? 0 : 1;
      for (Index d = 0; d < D; ++d)
        for (Index c = 0; c < 3; ++c) W_(v, 3 * d + c) = S(Wv(d, c));
    });
    for (char s : still) info_.still_vertices += s;
    trained_ = true;
  }

  /// Δx^H_i = Σ_j W_ij Δx^L_j for one frame (N×3 → M×3); allocates nothing.
  template <exec::HostPolicy Policy>
  void apply(Policy policy, const ConstPointsRef<S>& lr_displacement, PointsRef<S> hr_displacement) const {
    if (!trained_) throw ArgumentError("LocalLinear::apply before train");
    if (lr_displacement.rows() != n_) throw ShapeError("LocalLinear::apply: LR displacement", {n_, 3}, {lr_displacement.rows(), 3});
    if (hr_displacement.rows() != m_) throw ShapeError("LocalLinear::apply: HR displacement", {m_, 3}, {hr_displacement.rows(), 3});
    exec::parallel_for(policy, m_,
                       detail::LocalLinearRow<S>{idx_.data(), W_.data(), options_.k,
                                                 {lr_displacement.data(), n_, 3, lr_displacement.outerStride()},
                                                 {hr_displacement.data(), m_, 3, hr_displacement.outerStride()}});
  }

  /// M×k LR neighbour ids and the M × 9k per-vertex 3×3 maps (row v, entry (3k + a)·3 + c: (W_vk)_{ca})
  /// after train: what apply gathers with (DeviceLocalLinear copies them).
  const auto& neighbor_indices() const { return idx_; }
  const auto& vertex_maps() const { return W_; }
  bool trained() const { return trained_; }

  /// The whole map as a 3M×3N sparse matrix on displacements flattened row by row (x, y, z of
  /// vertex 0, then vertex 1, …): row 3i + c, column 3j + a holds (W_ij)_{ca}.
  Eigen::SparseMatrix<double, Eigen::RowMajor> linear_map() const {
    if (!trained_) throw ArgumentError("LocalLinear::linear_map before train");
    const Index K = options_.k;
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(std::size_t(m_ * K * 9));
    for (Index v = 0; v < m_; ++v)
      for (Index k = 0; k < K; ++k)
        for (Index a = 0; a < 3; ++a)
          for (Index c = 0; c < 3; ++c) t.emplace_back(3 * v + c, 3 * idx_(v, k) + a, double(W_(v, 3 * (3 * k + a) + c)));
    Eigen::SparseMatrix<double, Eigen::RowMajor> out(3 * m_, 3 * n_);
    out.setFromTriplets(t.begin(), t.end());
    return out;
  }

  const LocalLinearTrainInfo& info() const { return info_; }
  const LocalLinearOptions& options() const { return options_; }
  Index num_lr() const { return n_; }
  Index num_hr() const { return m_; }

 private:
  /// One vertex's normal equations, split by fold: G_f = A_fᵀA_f, B_f = A_fᵀY_f, ‖Y_f‖².
  struct VertexSystem {
    Index D, nf;
    std::vector<Eigen::MatrixXd> G, B;
    std::vector<double> yy;
    Eigen::MatrixXd G_total, B_total;

    VertexSystem(const LocalLinear& self, const data::PairedFrames<S>& frames, Index v, Index D_, Index nf_, const std::vector<Index>& fold)
        : D(D_), nf(nf_), G(std::size_t(nf_), Eigen::MatrixXd::Zero(D_, D_)), B(std::size_t(nf_), Eigen::MatrixXd::Zero(D_, 3)), yy(std::size_t(nf_), 0.0) {
      const Index F = frames.num_frames(), K = D / 3;
      Eigen::VectorXd a(D);
      Eigen::RowVector3d y;
      for (Index f = 0; f < F; ++f) {
        for (Index k = 0; k < K; ++k)
          for (Index c = 0; c < 3; ++c) a[3 * k + c] = double(frames.lowres(f, 3 * self.idx_(v, k) + c));
        for (Index c = 0; c < 3; ++c) y[c] = double(frames.highres(f, 3 * v + c));
        const auto j = std::size_t(fold[std::size_t(f)]);
        G[j].template selfadjointView<Eigen::Lower>().rankUpdate(a);
        B[j].noalias() += a * y;
        yy[j] += y.squaredNorm();
      }
      G_total = Eigen::MatrixXd::Zero(D, D);
      B_total = Eigen::MatrixXd::Zero(D, 3);
      for (Index j = 0; j < nf; ++j) {
        const Eigen::MatrixXd full = G[std::size_t(j)].template selfadjointView<Eigen::Lower>();
        G[std::size_t(j)] = full;
        G_total += G[std::size_t(j)];
        B_total += B[std::size_t(j)];
      }
    }

    /// (Gt + λ·tr(Gt)/D·I)⁻¹ Bt; zero when the neighbours never moved (tr Gt = 0).
    Eigen::MatrixXd solve(const Eigen::MatrixXd& Gt, const Eigen::MatrixXd& Bt, double lambda) const {
      const double t = Gt.trace() / double(D);
      if (!(t > 0)) return Eigen::MatrixXd::Zero(D, 3);
      Eigen::MatrixXd A = Gt;
      A.diagonal().array() += std::max(lambda, std::numeric_limits<double>::min()) * t;
      Eigen::LLT<Eigen::MatrixXd> llt(A);
      if (llt.info() != Eigen::Success) {  // λ below rounding on a singular Gram: the pseudo-inverse's limit
        Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
        return ldlt.solve(Bt);
      }
      return llt.solve(Bt);
    }

    /// Σ over folds of the held-out squared error of the map fitted on the other folds.
    double held_out_error(double lambda) const {
      double e = 0;
      for (Index j = 0; j < nf; ++j) {
        const auto& Gj = G[std::size_t(j)];
        const auto& Bj = B[std::size_t(j)];
        const Eigen::MatrixXd W = solve(G_total - Gj, B_total - Bj, lambda);
        // ‖A_j W − Y_j‖² = tr(Wᵀ G_j W) − 2 tr(Wᵀ B_j) + ‖Y_j‖²
        e += (W.transpose() * Gj * W).trace() - 2.0 * (W.transpose() * Bj).trace() + yy[std::size_t(j)];
      }
      return e;
    }
  };

  /// Fold of each frame: its sequence when two or more are named, else contiguous blocks.
  static std::vector<Index> assign_folds(const data::PairedFrames<S>& frames, Index folds, bool& by_sequence) {
    const Index F = frames.num_frames();
    std::vector<Index> fold(static_cast<std::size_t>(F), 0);
    std::map<std::int32_t, Index> seq;
    for (auto s : frames.sequence) seq.emplace(s, 0);
    if (seq.size() >= 2) {
      Index i = 0;
      for (auto& [s, j] : seq) j = i++;
      for (Index f = 0; f < F; ++f) fold[std::size_t(f)] = seq.at(frames.sequence[std::size_t(f)]);
      by_sequence = true;
      return fold;
    }
    if (folds < 2 || folds > F)
      throw ArgumentError("LocalLinear::train: cross-validation needs 2 <= folds <= frames (folds = " + std::to_string(folds) +
                          ", frames = " + std::to_string(F) + "), or a given λ");
    for (Index f = 0; f < F; ++f) fold[std::size_t(f)] = f * folds / F;
    by_sequence = false;
    return fold;
  }

  LocalLinearOptions options_;
  Eigen::Matrix<VIndex, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> idx_;  ///< M×k neighbours
  Index n_ = 0, m_ = 0;
  Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> W_;  ///< M × (3k·3): row v, (3k + a)·3 + c
  LocalLinearTrainInfo info_;
  bool trained_ = false;
};

static_assert(assert_trainable_interpolator<LocalLinear<>>());

}  // namespace simsr::interp
