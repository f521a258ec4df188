#pragma once
/// \file
/// Moving least squares over the §3.2 upsampling neighbourhoods (Park et al. 2023, appendix A.3,
/// Eq. 12–16), in two variants:
///  - `MlsBasis::per_coordinate` (default, the paper as written): each displacement component c is
///    fitted by a 1-D polynomial b(t) = [1, t, …, t^r] (r = 2) of the same coordinate only,
///    re-centred at the HR vertex, t = y_k^L − y_j^H (Eq. 16: Δy_j^H = c₀);
///  - `MlsBasis::linear_3d`: the textbook MLS with the re-centred 3-D linear basis [1, x, y, z],
///    one system per HR vertex shared by the three components.
/// Weights w_k = exp(−D_k²/σ²) of the geodesic distance D of the neighbourhoods (Eq. 14).
///
/// Both are linear in ΔX^L: c₀ = e₀ᵀ M⁻¹ Σ_k w_k b_k ΔX_k = Σ_k α_k ΔX_k with α_k = w_k e₀ᵀ M⁻¹ b_k.
/// fit() computes the α once (M×3×k, resp. M×k); apply() is a sparse gather, no solve per frame.
///
///     interp::MLS<> mls;            // as written: r = 2, per coordinate
///     mls.fit(exec::omp, problem);            // problem.neighborhoods present (k ≥ 20)
///     mls.apply(exec::omp, lr_displacement, hr_displacement);

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "concepts.hpp"
#include "detail/kernel.hpp"

namespace simsr::interp {

/// Polynomial basis of MLS.
enum class MlsBasis {
  per_coordinate,  ///< A.3 as written: per component, 1-D basis in that coordinate, degree r
  linear_3d,       ///< [1, x, y, z] re-centred, one system for the three components
};

/// Parameters of MLS.
struct MLSOptions {
  MlsBasis basis = MlsBasis::per_coordinate;
  int degree = 2;      ///< r of the per_coordinate basis (0..3; the paper's r = 2); linear_3d ignores it
  Index k = 20;        ///< neighbours per HR vertex (the paper's 20, "the same as §3.2")
  /// σ_MLS of Eq. 14 (units of the positions); ≤ 0: sigma_scale × the mean over HR vertices of the
  /// distance to the k-th neighbour. The paper gives no value; this default keeps all k
  /// neighbours in the fit (weight ≥ ~e⁻¹ at the neighbourhood's edge) while favouring near ones,
  /// so the quadratic fit stays well posed.
  double sigma = 0;
  double sigma_scale = 1.0;
  /// A moment matrix (in the basis scaled by the largest |t| of the neighbourhood) whose
  /// eigenvalue ratio λmin/λmax is below this is treated as singular.
  double min_rcond = 1e-10;
};

/// What fit() found.
struct MLSFitInfo {
  double sigma = 0;  ///< σ used
  /// per_coordinate: number of (HR vertex, component) systems solved at degree 0, 1, 2, 3 (fewer
  /// than `degree` means a singular moment matrix, e.g. all neighbours on one coordinate plane).
  std::array<Index, 4> systems_at_degree{};
  /// linear_3d: HR vertices whose 4×4 moment matrix was rank deficient (coplanar or collinear
  /// neighbours), solved with the pseudo-inverse (eigenvalues below min_rcond·λmax dropped).
  /// c₀ is then still exact for linear fields when the HR vertex lies in the neighbours' plane.
  Index rank_deficient = 0;
};

/// MLS interpolator (S = double or float; the fit runs in double). Thread safety: apply is const.
template <class S = Scalar>
class MLS {
 public:
  using scalar_type = S;
  /// fit reads problem.neighborhoods.
  static constexpr bool needs_neighborhoods = true;

  MLS() = default;
  explicit MLS(MLSOptions options) : options_(options) {}

  /// Per HR vertex coefficients α from the rest shapes and the first k neighbours of
  /// `problem.neighborhoods`. ArgumentError for a bad option or missing neighbourhoods.
  template <exec::HostPolicy Policy>
  void fit(Policy policy, UpsamplingProblem<S>& problem) {
    const auto& o = options_;
    if (o.basis == MlsBasis::per_coordinate && (o.degree < 0 || o.degree > 3))
      throw ArgumentError("MLS: degree r = " + std::to_string(o.degree) + " outside [0, 3]");
    if (!(o.min_rcond > 0 && o.min_rcond < 1)) throw ArgumentError("MLS: min_rcond must lie in (0, 1)");
    const auto& nb = detail::neighborhoods_for(problem, o.k, "MLS");
    const Index m = problem.num_hr(), k = o.k;
    info_ = {};
    info_.sigma = o.sigma > 0 ? o.sigma : o.sigma_scale * nb.distances.col(k - 1).mean();
    if (!(info_.sigma > 0) || !std::isfinite(info_.sigma))
      throw ArgumentError("MLS: sigma = " + std::to_string(info_.sigma) + " must be finite and > 0");

    gather_.indices = nb.indices.leftCols(k);
    gather_.per_component = o.basis == MlsBasis::per_coordinate;
    gather_.weights.resize(m, gather_.per_component ? 3 * k : k);
    std::vector<int> flag(static_cast<std::size_t>(3 * m), 0);  // degree used, or rank deficiency
    const auto& L = problem.lr.V;
    const auto& H = problem.hr.V;
    exec::parallel_for(policy, m, [&](Index j) {
      Eigen::VectorXd w(k);
      const double d0 = nb.distances(j, 0), s2 = info_.sigma * info_.sigma;
      // relative to the nearest neighbour: a common factor, c₀ is unchanged, no underflow
      for (Index n = 0; n < k; ++n) w(n) = std::exp(-(nb.distances(j, n) - d0) * (nb.distances(j, n) + d0) / s2);
      Eigen::MatrixXd t(k, 3);
      for (Index n = 0; n < k; ++n)
        t.row(n) = L.row(nb.indices(j, n)).template cast<double>() - H.row(j).template cast<double>();
      if (gather_.per_component) {
        for (int c = 0; c < 3; ++c) {
          const int r = fit_1d(w, t.col(c), j, c);
          flag[static_cast<std::size_t>(3 * j + c)] = r;
        }
      } else {
        flag[static_cast<std::size_t>(3 * j)] = fit_linear_3d(w, t, j);
      }
    });
    if (gather_.per_component) {
      for (int f : flag) ++info_.systems_at_degree[static_cast<std::size_t>(f)];
    } else {
      for (Index j = 0; j < m; ++j) info_.rank_deficient += flag[static_cast<std::size_t>(3 * j)];
    }
    n_ = problem.num_lr();
  }

  /// hr_displacement (M×3, caller-sized) from lr_displacement (N×3): Δx_j^H = Σ_k α_jk ΔX_k^L
  /// (Eq. 16 per component). ShapeError for wrong sizes.
  template <exec::HostPolicy Policy>
  void apply(Policy policy, const ConstPointsRef<S>& lr_displacement, PointsRef<S> hr_displacement) const {
    detail::check_apply_shapes("MLS::apply", n_, num_hr(), lr_displacement, hr_displacement);
    gather_.apply(policy, lr_displacement, hr_displacement);
  }

  Index num_lr() const { return n_; }
  Index num_hr() const { return gather_.rows(); }
  /// The fitted gather apply runs (DeviceNeighborGather copies it).
  const detail::NeighborGather<S>& gather() const { return gather_; }
  const MLSOptions& options() const { return options_; }
  const MLSFitInfo& info() const { return info_; }
  /// M×k LR ids; coefficients α: M×3k (per_coordinate, component c in columns [c·k, c·k+k)) or M×k.
  const auto& indices() const { return gather_.indices; }
  const auto& coefficients() const { return gather_.weights; }

 private:
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 4, 4>;
  using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 4, 1>;

#if defined(__GNUC__) && !defined(__clang__)
// GCC 12 reports a false -Warray-bounds inside Eigen's SSE loads for these fixed-max (≤ 4)
// dynamic vectors; the sizes are r + 1 ≤ 4 by construction (MLSOptions::degree is checked).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Warray-bounds"
#endif
  /// Eq. 15–16 for one component: α_n = w_n e₀ᵀ M⁻¹ b(τ_n), τ = t / max|t| (the scaling leaves c₀
  /// unchanged). Lowers the degree while M is singular; returns the degree used.
  int fit_1d(const Eigen::VectorXd& w, const Eigen::VectorXd& t, Index j, int c) {
    const Index k = w.size();
    const double scale = t.cwiseAbs().maxCoeff();
    int r = scale > 0 ? options_.degree : 0;
    const Eigen::VectorXd tau = scale > 0 ? Eigen::VectorXd(t / scale) : Eigen::VectorXd::Zero(k);
    SmallVec g;
    for (;; --r) {
      Small M = Small::Zero(r + 1, r + 1);
      for (Index n = 0; n < k; ++n) {
        const SmallVec b = basis_1d(tau(n), r);
        M.noalias() += w(n) * b * b.transpose();
      }
      Eigen::SelfAdjointEigenSolver<Small> es(M);
      const auto& lam = es.eigenvalues();
      if (r == 0 || lam(0) > options_.min_rcond * lam(r)) {
        const SmallVec e0 = es.eigenvectors().row(0).transpose();
        g = es.eigenvectors() * e0.cwiseQuotient(lam);  // M⁻¹ e₀
        break;
      }
    }
    S* a = gather_.weights.data() + j * 3 * k + c * k;
    for (Index n = 0; n < k; ++n) a[n] = S(w(n) * g.dot(basis_1d(tau(n), r)));
    return r;
  }

  static SmallVec basis_1d(double tau, int r) {
    SmallVec b(r + 1);
    b(0) = 1;
    for (int p = 1; p <= r; ++p) b(p) = b(p - 1) * tau;
    return b;
  }

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

  /// The 3-D linear MLS: α_n = w_n e₀ᵀ M⁺ [1, τ_n], τ = t / max‖t‖. Returns 1 when M was rank deficient.
  int fit_linear_3d(const Eigen::VectorXd& w, const Eigen::MatrixXd& t, Index j) {
    const Index k = w.size();
    const double scale = t.rowwise().norm().maxCoeff();
    const double inv = scale > 0 ? 1 / scale : 0;
    Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
    for (Index n = 0; n < k; ++n) {
      Eigen::Vector4d b(1, t(n, 0) * inv, t(n, 1) * inv, t(n, 2) * inv);
      M.noalias() += w(n) * b * b.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(M);
    const Eigen::Vector4d lam = es.eigenvalues();
    Eigen::Vector4d inv_lam;
    int deficient = 0;
    for (int i = 0; i < 4; ++i) {
      const bool keep = lam(i) > options_.min_rcond * lam(3);
      inv_lam(i) = keep ? 1 / lam(i) : 0;
      deficient |= !keep;
    }
    const Eigen::Vector4d g = es.eigenvectors() * inv_lam.cwiseProduct(es.eigenvectors().row(0).transpose());
    for (Index n = 0; n < k; ++n) {
      Eigen::Vector4d b(1, t(n, 0) * inv, t(n, 1) * inv, t(n, 2) * inv);
      gather_.weights(j, n) = S(w(n) * g.dot(b));
    }
    return deficient;
  }

  MLSOptions options_;
  MLSFitInfo info_;
  detail::NeighborGather<S> gather_;
  Index n_ = 0;
};

static_assert(assert_interpolator<MLS<double>>());
static_assert(assert_interpolator<MLS<float>>());

}  // namespace simsr::interp
