#pragma once
/// \file
/// Inverse distance weighting over the §3.2 upsampling neighbourhoods: Eq. (1) with the fixed
/// weights w_ij ∝ 1/D_ij^p, D the geodesic distance of the neighbourhoods (the paper names IDW as
/// one choice of w_ij in §3.2).
///
///     interp::UpsamplingProblem<> p{lr_rest, hr_rest};
///     p.ensure_neighborhoods(exec::omp, 20);
///     interp::IDW<> idw;  idw.fit(exec::omp, p);
///     idw.apply(exec::omp, lr_displacement, hr_displacement);   // N×3 → M×3

#include <algorithm>
#include <cmath>
#include <string>

#include "concepts.hpp"
#include "detail/kernel.hpp"

namespace simsr::interp {

/// Parameters of IDW.
struct IDWOptions {
  Index k = 20;        ///< neighbours used per HR vertex (first k columns of the neighbourhoods; the paper's 20)
  double power = 2.0;  ///< p in w ∝ 1/D^p (> 0); larger p favours the nearest neighbour
  /// A neighbour at D ≤ hit_distance is an exact hit: weight 1 on it (the first such), 0 elsewhere.
  double hit_distance = 0.0;
};

/// IDW interpolator (S = double or float). fit() stores per HR vertex k weights that sum to 1;
/// apply() is an M×k gather. Thread safety: apply is const and may run concurrently.
template <class S = Scalar>
class IDW {
 public:
  using scalar_type = S;
  /// fit reads problem.neighborhoods.
  static constexpr bool needs_neighborhoods = true;

  IDW() = default;
  explicit IDW(IDWOptions options) : options_(options) {}

  /// Weights from the first k neighbours of `problem.neighborhoods` (must be present).
  /// ArgumentError for p ≤ 0 or missing/too small neighbourhoods, ShapeError for a size mismatch.
  template <exec::HostPolicy Policy>
  void fit(Policy, UpsamplingProblem<S>& problem) {  // O(M·k): sequential under any policy
    if (!(options_.power > 0)) throw ArgumentError("IDW: power p = " + std::to_string(options_.power) + " must be > 0");
    const auto& nb = detail::neighborhoods_for(problem, options_.k, "IDW");
    const Index m = problem.num_hr(), k = options_.k;
    gather_.indices = nb.indices.leftCols(k);
    gather_.weights.resize(m, k);
    gather_.per_component = false;
    for (Index j = 0; j < m; ++j) {
      auto w = gather_.weights.row(j);
      if (nb.distances(j, 0) <= std::max(options_.hit_distance, 0.0)) {  // ascending rows: the nearest is the hit
        w.setZero();
        w(0) = S(1);
        continue;
      }
      double sum = 0;
      // scale by the nearest distance first: 1/(D/D0)^p ≤ 1 cannot overflow for tiny D
      const double d0 = nb.distances(j, 0);
      Eigen::Matrix<double, 1, Eigen::Dynamic> wd(k);
      for (Index n = 0; n < k; ++n) sum += wd(n) = std::pow(d0 / nb.distances(j, n), options_.power);
      w = (wd / sum).template cast<S>();
    }
    n_ = problem.num_lr();
  }

  /// hr_displacement (M×3, caller-sized) from lr_displacement (N×3); ShapeError otherwise.
  template <exec::HostPolicy Policy>
  void apply(Policy policy, const ConstPointsRef<S>& lr_displacement, PointsRef<S> hr_displacement) const {
    detail::check_apply_shapes("IDW::apply", n_, num_hr(), lr_displacement, hr_displacement);
    gather_.apply(policy, lr_displacement, hr_displacement);
  }

  Index num_lr() const { return n_; }
  Index num_hr() const { return gather_.rows(); }
  /// The fitted gather apply runs (DeviceNeighborGather copies it).
  const detail::NeighborGather<S>& gather() const { return gather_; }
  const IDWOptions& options() const { return options_; }
  /// M×k LR ids and M×k weights (rows sum to 1) after fit.
  const auto& indices() const { return gather_.indices; }
  const auto& weights() const { return gather_.weights; }

 private:
  IDWOptions options_;
  detail::NeighborGather<S> gather_;
  Index n_ = 0;
};

static_assert(assert_interpolator<IDW<double>>());
static_assert(assert_interpolator<IDW<float>>());

}  // namespace simsr::interp
