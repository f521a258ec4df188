#pragma once
/// \file
/// Gaussian radial basis function interpolation of LR displacements onto the HR surface
/// (Park et al. 2023, appendix A.2, Eq. 8–11): solve Φ_LL W = ΔX^L over all N LR vertices
/// (Eq. 10, global), evaluate Δx^H = Φ_HL W (Eq. 11), φ(R) = exp(−R²/σ²) (Eq. 9).
///
/// Distances (`RbfDistance`):
///  - geodesic (default): A.2's "compute R geodesically following §3.2", in one metric: LR vertex i
///    sits at HR vertex lr_to_hr[i] (problem.neighborhoods), and Φ_LL(i,k) = φ(d(lr_to_hr[i],
///    lr_to_hr[k])), Φ_HL(j,k) = φ(d(j, lr_to_hr[k])), d the shortest path over the HR rest
///    surface's edges (the §3.2 neighbourhood distances). One Dijkstra per LR vertex, stopped at
///    σ·sqrt(ln 1/truncation), gives both; entries beyond it are 0 in Φ_LL and Φ_HL alike, so
///    Φ_HL's row at lr_to_hr[i] is Φ_LL's row i and the prediction there is ΔX^L_i (Eq. 10 → 11).
///    The tail's monomials are evaluated at the mapped positions for the same reason.
///  - lr_mesh_geodesic: the literal but inconsistent reading (Φ_LL along LR tet edges, Φ_HL the
///    first k neighbourhood distances); kept for comparison, see the enum for why not the default.
///  - euclidean: |x − y| for both, every HR–LR entry kept in the dense path (scipy's
///    RBFInterpolator(kernel='gaussian', epsilon=1/σ) computes the same interpolant).
/// Optional polynomial tail (`degree` 0 or 1) in the standard saddle-point form
///     [Φ_LL + λI  P; Pᵀ 0] [W; c] = [ΔX^L; 0],   Δx^H = Φ_HL W + P_H c,
/// the monomials in coordinates shifted to the LR bounding-box centre and scaled by its half
/// extents (scipy's convention; the interpolant itself does not depend on it).
///
/// Linear in ΔX^L, so fit() precomputes what it can:
///  - dense path (N + P ≤ dense_max, default): LU of the (N+P)² system (LAPACK's dgesv, as
///    scipy). When M·N·sizeof(S) ≤ max_operator_bytes (512 MiB) the evaluation operator
///    A = [Φ_HL P_H] K⁻¹[:, :N] (M×N) is formed and apply() is one product, no solve;
///    otherwise the LU is kept and apply() does two triangular solves per component.
///  - sparse path (larger N, e.g. the paper's N = 15,872, whose dense Φ would take 2 GB): kernel
///    entries below `truncation` (R > σ·sqrt(ln 1/truncation)) are dropped, Φ_LL is factored by
///    Eigen's SimplicialLDLT (AMD ordering) and apply() does the sparse triangular solves per
///    frame, then the sparse Φ_HL product. Needs σ small against the mesh (the default is).
///
///     interp::RBF<> rbf;                      // geodesic, σ = mapped-centre spacing, no tail
///     rbf.fit(exec::omp, problem);                       // problem.neighborhoods (with lr_to_hr), hr.F present
///     rbf.apply(exec::omp, lr_displacement, hr_displacement);

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "../core/eigen_threads.hpp"
#include "concepts.hpp"
#include "detail/kernel.hpp"
#include "detail/rbf_distances.hpp"

namespace simsr::interp {

/// Distance measure R of the kernel (Eq. 8–11).
enum class RbfDistance {
  /// A.2 "geodesically following §3.2", consistently: every distance is a shortest path over the
  /// HR rest surface's edges between mapped positions (LR vertex i at HR vertex lr_to_hr[i]), for
  /// Φ_LL (Eq. 10) and Φ_HL (Eq. 11) alike; entries beyond σ·sqrt(ln 1/truncation) are 0 on both.
  geodesic,
  /// The literal but inconsistent reading: Φ_LL along the LR tet-mesh edges, Φ_HL from the §3.2
  /// neighbourhoods (HR surface paths to mapped vertices, first k only). The two metrics disagree,
  /// and the ill-conditioned solve amplifies it: on the bunny (frames 10/100/200/250, σ = mean LR
  /// edge) mean error 0.14 with our mapping, 0.15 with the authors', vs 0.0049 for "HR stays at
  /// rest". Kept for comparison only.
  lr_mesh_geodesic,
  euclidean,  ///< straight-line distance for both (the scipy-comparable form)
};

/// How Φ_LL is factored.
enum class RbfSolver {
  automatic,  ///< dense when N + P ≤ dense_max, sparse otherwise
  dense,      ///< full (N+P)² LU, no truncation of Φ_LL
  sparse,     ///< truncated Φ_LL, sparse LDLᵀ
};

/// Parameters of RBF.
struct RBFOptions {
  RbfDistance distance = RbfDistance::geodesic;
  /// σ_RBF of Eq. 9 (units of the positions); ≤ 0: sigma_scale × the spacing h of the centres in
  /// the metric used: geodesic, the mean HR-surface distance from each mapped LR vertex to the
  /// nearest other one; lr_mesh_geodesic and euclidean, the mean LR edge length. σ ≈ h keeps Φ_LL
  /// well conditioned (the smallest eigenvalue of a Gaussian matrix falls like exp(−c σ²/h²)) and
  /// sparse after truncation, while a centre still reaches its nearest neighbours with weight e⁻¹.
  /// Bunny, geodesic, frames 10/100/200/250: mean error 0.0022 at σ = h (0.45× rest), 0.0029 at
  /// 1.5h, 0.012 at the mean LR edge (3.7h: the mapped centres are ~3.7× denser on the surface).
  double sigma = 0;
  double sigma_scale = 1.0;
  int degree = -1;              ///< polynomial tail: −1 none (the paper), 0 constant, 1 linear
  double regularization = 0;    ///< λ added to Φ_LL's diagonal (scipy's `smoothing`); 0 interpolates exactly
  RbfSolver solver = RbfSolver::automatic;
  Index dense_max = 4096;       ///< automatic: dense when N + P ≤ this ((N+P)² doubles: 134 MB at 4096)
  double truncation = 1e-10;    ///< sparse path: kernel values below this are dropped
  std::size_t max_operator_bytes = std::size_t(512) << 20;  ///< dense path: form the M×N operator up to this
  double min_rcond = 1e-14;     ///< a smaller reciprocal condition estimate is an ArgumentError
  Index k = 20;                 ///< lr_mesh_geodesic HR–LR entries: first k neighbours
};

/// What fit() chose and found.
struct RBFFitInfo {
  double sigma = 0;                                               ///< σ used
  double cutoff_radius = std::numeric_limits<double>::infinity();  ///< kernel support kept (sparse path, geodesic)
  bool sparse = false;                ///< sparse LDLᵀ path taken
  bool precomputed_operator = false;  ///< apply() is one M×N product
  Index lr_nonzeros = 0;              ///< stored entries of the factored system (lower triangle when sparse)
  Index factor_nonzeros = 0;          ///< entries of the sparse factor L (sparse path)
  Index hr_nonzeros = 0;              ///< stored entries of Φ_HL
  double rcond = 0;                   ///< dense: LU's reciprocal condition estimate; sparse: min|D|/max|D|
};

/// RBF interpolator (S = double or float; systems are solved in double). Thread safety: apply is
/// const but, without a precomputed operator, works in buffers of the object: one apply at a
/// time per object.
template <class S = Scalar>
class RBF {
 public:
  using scalar_type = S;
  /// fit reads problem.neighborhoods.
  static constexpr bool needs_neighborhoods = true;

  RBF() = default;
  explicit RBF(RBFOptions options) : options_(options) {}

  /// Builds and factors the kernel system on the rest shapes (see the file comment for the
  /// paths). Geodesic mode needs `problem.neighborhoods` with lr_to_hr and the HR triangles;
  /// lr_mesh_geodesic the neighbourhoods (k columns) and LR tets. Throws ArgumentError for a
  /// bad option or a numerically singular system (duplicate LR vertices, σ too large, a
  /// polynomial tail on coplanar centres).
  template <exec::HostPolicy Policy>
  void fit(Policy policy, UpsamplingProblem<S>& problem) {
    const auto& o = options_;
    if (o.degree < -1 || o.degree > 1) throw ArgumentError("RBF: degree = " + std::to_string(o.degree) + " outside {-1, 0, 1}");
    if (!(o.regularization >= 0)) throw ArgumentError("RBF: regularization must be ≥ 0");
    if (!(o.truncation > 0 && o.truncation < 1)) throw ArgumentError("RBF: truncation must lie in (0, 1)");
    const bool surface = o.distance == RbfDistance::geodesic;
    const bool lr_mesh = o.distance == RbfDistance::lr_mesh_geodesic;
    const auto& L = problem.lr.V;
    const auto& H = problem.hr.V;
    n_ = problem.num_lr();
    m_ = problem.num_hr();
    p_ = o.degree < 0 ? 0 : o.degree == 0 ? 1 : 4;
    const Index np = n_ + p_;
    if (n_ < 1) throw ArgumentError("RBF: no LR vertices");
    info_ = {};
    std::span<const VIndex> lr_to_hr;
    neighbors::WeightedGraph surface_graph;
    if (surface) {
      lr_to_hr = checked_lr_to_hr(problem);
      surface_graph = neighbors::surface_edge_graph(H, problem.hr.F);
    }
    if (o.sigma > 0) {
      info_.sigma = o.sigma;
    } else if (surface) {
      const double spacing = detail::mean_nearest_source_distance(policy, surface_graph, lr_to_hr);
      if (!(spacing > 0))
        throw ArgumentError("RBF (geodesic): no two mapped LR vertices are connected over the HR surface, so no default "
                            "kernel width; set sigma explicitly");
      info_.sigma = o.sigma_scale * spacing;
    } else {
      info_.sigma = o.sigma_scale * detail::mean_edge_length(L, problem.lr.T, "RBF");
    }
    if (!(info_.sigma > 0) || !std::isfinite(info_.sigma)) throw ArgumentError("RBF: sigma must be finite and > 0");
    const double sigma = info_.sigma;
    info_.sparse = o.solver == RbfSolver::sparse || (o.solver == RbfSolver::automatic && np > o.dense_max);
    // geodesic (surface) mode truncates on every path, so Φ_LL and Φ_HL drop the same entries
    if (info_.sparse || surface) info_.cutoff_radius = sigma * std::sqrt(std::log(1 / o.truncation));
    const auto* nb = lr_mesh ? &detail::neighborhoods_for(problem, o.k, "RBF (lr_mesh_geodesic)") : nullptr;

    // centre positions (the tail's monomials): the LR vertices, or where they are mapped to
    Points<double> C(n_, 3);
    for (Index i = 0; i < n_; ++i)
      C.row(i) = surface ? H.row(lr_to_hr[std::size_t(i)]).template cast<double>() : L.row(i).template cast<double>();
    const Eigen::RowVector3d lo = C.colwise().minCoeff();
    const Eigen::RowVector3d hi = C.colwise().maxCoeff();
    shift_ = (hi + lo) / 2;
    scale_ = (hi - lo) / 2;
    for (int c = 0; c < 3; ++c)
      if (scale_(c) == 0) scale_(c) = 1;

    // Geodesic (surface): one radius-limited Dijkstra per LR vertex k from lr_to_hr[k] over the HR
    // surface gives column k of Φ_HL and, at the mapped vertices, column k of Φ_LL. Φ_LL(i, k),
    // i ≥ k, comes from source k; Φ_HL's row at lr_to_hr[i] is copied from Φ_LL's row i, so the
    // two agree bit for bit and Δx^H at lr_to_hr[i] reproduces ΔX^L_i up to the solve's rounding.
    std::vector<detail::DistanceRow> ll_lower, hl_cols;  // surface mode: per source (i ≥ s), (HR vertex, d)
    if (surface) {
      std::vector<VIndex> hr_to_lr(static_cast<std::size_t>(m_), -1);
      for (Index i = 0; i < n_; ++i) hr_to_lr[std::size_t(lr_to_hr[std::size_t(i)])] = VIndex(i);
      const auto& g = surface_graph;
      ll_lower.resize(std::size_t(n_));
      hl_cols.resize(std::size_t(n_));
      detail::surface_rows(policy, g, lr_to_hr, info_.cutoff_radius, [&](Index s, const detail::DistanceRow& row) {
        auto& ll = ll_lower[std::size_t(s)];
        auto& hl = hl_cols[std::size_t(s)];
        for (const auto& [v, d] : row) {
          const VIndex i = hr_to_lr[std::size_t(v)];
          if (i < 0)
            hl.emplace_back(v, d);
          else if (i >= s)
            ll.emplace_back(i, d);
        }
        std::sort(ll.begin(), ll.end());
      });
    }
    detail::RbfEdgeGraph graph;
    if (lr_mesh) graph = detail::rbf_edge_graph(L, problem.lr.T);
    const auto lr_rows = [&](auto&& sink) {
      if (surface) {
        exec::parallel_for(policy, n_, [&](Index s) { sink(s, ll_lower[std::size_t(s)]); });
      } else if (lr_mesh) {
        detail::geodesic_rows(policy, graph, info_.cutoff_radius, sink);
      } else {
        detail::euclidean_rows(policy, L, L, info_.cutoff_radius, sink);
      }
    };

    lu_ = {};
    ldlt_.reset();
    A_.resize(0, 0);
    if (!info_.sparse) {
      Eigen::MatrixXd K = Eigen::MatrixXd::Zero(np, np);
      // source s writes K(i, s) and K(s, i) for i ≥ s only: no two sources write one entry
      lr_rows([&](Index s, const detail::DistanceRow& row) {
        for (const auto& [i, d] : row)
          if (i >= s) K(i, s) = K(s, i) = detail::gaussian(d, sigma);
      });
      for (Index i = 0; i < n_; ++i) {
        K(i, i) += o.regularization;
        const auto mono = monomials(C.row(i));
        for (Index q = 0; q < p_; ++q) K(i, n_ + q) = K(n_ + q, i) = mono(q);
      }
      info_.lr_nonzeros = np * np;
      const EigenSingleThreaded eigen_serial;  // the blocked LU's GEMM would start threads of its own
      lu_.compute(K);
      info_.rcond = lu_.rcond();
      check_rcond();
    } else {
      std::vector<std::vector<Eigen::Triplet<double, int>>> lower(static_cast<std::size_t>(n_));
      lr_rows([&](Index s, const detail::DistanceRow& row) {
        auto& t = lower[static_cast<std::size_t>(s)];
        for (const auto& [i, d] : row)
          if (i >= s) t.emplace_back(int(i), int(s), detail::gaussian(d, sigma) + (i == s ? o.regularization : 0.0));
      });
      std::vector<Eigen::Triplet<double, int>> trip;
      for (auto& t : lower) trip.insert(trip.end(), t.begin(), t.end()), t = {};
      for (Index i = 0; i < n_; ++i) {
        const auto mono = monomials(C.row(i));
        for (Index q = 0; q < p_; ++q) trip.emplace_back(int(n_ + q), int(i), mono(q));
      }
      Eigen::SparseMatrix<double, Eigen::ColMajor, int> K(np, np);
      K.setFromTriplets(trip.begin(), trip.end());
      info_.lr_nonzeros = K.nonZeros();
      ldlt_ = std::make_unique<SparseLdlt>();
      ldlt_->compute(K);
      if (ldlt_->info() != Eigen::Success)
        throw ArgumentError("RBF: sparse LDLT of the truncated kernel system (" + std::to_string(np) + "², σ = " +
                            std::to_string(sigma) + ") failed: a zero pivot; lower sigma or add regularization");
      d_ = ldlt_->vectorD();
      info_.rcond = d_.cwiseAbs().minCoeff() / d_.cwiseAbs().maxCoeff();
      info_.factor_nonzeros = ldlt_->matrixL().nestedExpression().nonZeros();
      check_rcond();
    }

    // Φ_HL (Eq. 11) as CSR and the tail's monomials at the HR vertices
    std::vector<detail::DistanceRow> hr_rows(static_cast<std::size_t>(m_));
    if (surface) {
      for (Index s = 0; s < n_; ++s) {
        for (const auto& [v, d] : hl_cols[std::size_t(s)]) hr_rows[std::size_t(v)].emplace_back(VIndex(s), d);
        for (const auto& [i, d] : ll_lower[std::size_t(s)]) {
          hr_rows[std::size_t(lr_to_hr[std::size_t(i)])].emplace_back(VIndex(s), d);
          if (i != s) hr_rows[std::size_t(lr_to_hr[std::size_t(s)])].emplace_back(i, d);
        }
        hl_cols[std::size_t(s)] = {}, ll_lower[std::size_t(s)] = {};
      }
      exec::parallel_for(policy, m_, [&](Index j) { std::sort(hr_rows[std::size_t(j)].begin(), hr_rows[std::size_t(j)].end()); });
    } else if (lr_mesh) {
      for (Index j = 0; j < m_; ++j) {
        auto& r = hr_rows[static_cast<std::size_t>(j)];
        for (Index n = 0; n < o.k; ++n) r.emplace_back(nb->indices(j, n), nb->distances(j, n));
        std::sort(r.begin(), r.end());
      }
    } else {
      detail::euclidean_rows(policy, H, L, info_.cutoff_radius,
                             [&](Index j, const detail::DistanceRow& row) { hr_rows[static_cast<std::size_t>(j)] = row; });
    }
    phi_hl_.resize(m_, n_);
    {
      Index nnz = 0;
      for (const auto& r : hr_rows) nnz += Index(r.size());
      phi_hl_.reserve(nnz);
      for (Index j = 0; j < m_; ++j) {
        phi_hl_.startVec(j);
        for (const auto& [i, d] : hr_rows[static_cast<std::size_t>(j)]) phi_hl_.insertBack(j, i) = S(detail::gaussian(d, sigma));
        hr_rows[static_cast<std::size_t>(j)] = {};
      }
      phi_hl_.finalize();
    }
    info_.hr_nonzeros = phi_hl_.nonZeros();
    poly_h_.resize(m_, p_);
    for (Index j = 0; j < m_; ++j) poly_h_.row(j) = monomials(H.row(j)).template cast<S>();

    if (!info_.sparse && double(m_) * double(n_) * sizeof(S) <= double(o.max_operator_bytes)) {
      // A = E K⁻¹[:, :N] with E = [Φ_HL P_H]; K symmetric, so Aᵀ = (K⁻¹ Eᵀ)[:N, :], by blocks of HR rows
      A_.resize(m_, n_);
      const Index block = 512;
      Eigen::MatrixXd Et;
      for (Index b = 0; b < m_; b += block) {
        const Index nb_rows = std::min(block, m_ - b);
        Et.setZero(np, nb_rows);
        for (Index j = b; j < b + nb_rows; ++j) {
          for (typename HrMatrix::InnerIterator it(phi_hl_, j); it; ++it) Et(it.col(), j - b) = double(it.value());
          for (Index q = 0; q < p_; ++q) Et(n_ + q, j - b) = monomials(H.row(j))(q);
        }
        const Eigen::MatrixXd X = lu_.solve(Et);
        A_.middleRows(b, nb_rows) = X.topRows(n_).transpose().template cast<S>();
      }
      info_.precomputed_operator = true;
      lu_ = {};
      phi_hl_ = {};
      poly_h_.resize(0, 0);
    }
    work_.setZero(np, 3);
    weights_.setZero(np, 3);
  }

  /// hr_displacement (M×3, caller-sized) from lr_displacement (N×3), Eq. 10–11. ShapeError for
  /// wrong sizes.
  template <exec::HostPolicy Policy>
  void apply(Policy policy, const ConstPointsRef<S>& lr_displacement, PointsRef<S> hr_displacement) const {
    detail::check_apply_shapes("RBF::apply", n_, m_, lr_displacement, hr_displacement);
    const S* x = lr_displacement.data();
    S* y = hr_displacement.data();
    if (info_.precomputed_operator) {
      exec::parallel_for(policy, m_,
                         detail::DenseOperatorRow<S>{A_.data(), n_, {x, n_, 3, lr_displacement.outerStride()},
                                                     {y, m_, 3, hr_displacement.outerStride()}});
      return;
    }
    exec::parallel_for(policy, 3, [&](Index c) { solve_component(lr_displacement, int(c)); });
    const Index p = p_;
    const S* poly = poly_h_.data();
    const double* w = weights_.data();
    const Index ld = weights_.rows();
    const auto& phi = phi_hl_;
    const Index n = n_;
    exec::parallel_for(policy, m_, [&, n, p, poly, w, ld, y](Index j) {
      double a[3] = {0, 0, 0};
      for (typename HrMatrix::InnerIterator it(phi, j); it; ++it)
        for (int c = 0; c < 3; ++c) a[c] += double(it.value()) * w[c * ld + it.col()];
      for (Index q = 0; q < p; ++q)
        for (int c = 0; c < 3; ++c) a[c] += double(poly[j * p + q]) * w[c * ld + n + q];
      for (int c = 0; c < 3; ++c) y[3 * j + c] = S(a[c]);
    });
  }

  Index num_lr() const { return n_; }
  Index num_hr() const { return m_; }
  /// The M×N evaluation operator apply multiplies by (empty unless info().precomputed_operator;
  /// DeviceRbf copies it).
  const auto& evaluation_operator() const { return A_; }
  const RBFOptions& options() const { return options_; }
  const RBFFitInfo& info() const { return info_; }

 private:
  using SparseLdlt = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double, Eigen::ColMajor, int>, Eigen::Lower,
                                           Eigen::AMDOrdering<int>>;
  using HrMatrix = Eigen::SparseMatrix<S, Eigen::RowMajor, int>;

  /// problem.neighborhoods->lr_to_hr as a span, checked (N distinct HR vertices) together with
  /// the HR faces the geodesic mode walks on; ArgumentError naming what is missing.
  std::span<const VIndex> checked_lr_to_hr(const UpsamplingProblem<S>& problem) const {
    const Index n = problem.num_lr(), m = problem.num_hr();
    if (!problem.neighborhoods)
      throw ArgumentError("RBF (geodesic): the upsampling problem has no neighbourhoods, so no LR→HR mapping; call "
                          "problem.ensure_neighborhoods() or load saved ones first");
    const auto& map = problem.neighborhoods->lr_to_hr;
    if (map.size() != n)
      throw ArgumentError("RBF (geodesic): neighbourhoods' lr_to_hr has " + std::to_string(map.size()) + " entries, " +
                          std::to_string(n) + " LR vertices; the surface metric needs the LR→HR mapping of §3.2");
    std::vector<char> used(static_cast<std::size_t>(m), 0);
    for (Index i = 0; i < n; ++i) {
      const VIndex v = map[i];
      if (v < 0 || v >= m)
        throw ArgumentError("RBF (geodesic): lr_to_hr[" + std::to_string(i) + "] = " + std::to_string(v) + " outside [0, " +
                            std::to_string(m) + ")");
      if (used[std::size_t(v)]++)
        throw ArgumentError("RBF (geodesic): lr_to_hr maps two LR vertices onto HR vertex " + std::to_string(v) +
                            " (the mapping must be one-to-one)");
    }
    if (problem.hr.F.rows() == 0)
      throw ArgumentError("RBF (geodesic): the HR surface has no triangles to measure geodesic distances on");
    return {map.data(), std::size_t(n)};
  }

  /// Tail monomials at a point: [], [1] or [1, x̂, ŷ, ẑ] with x̂ = (x − shift)/scale.
  Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, 4> monomials(const auto& point) const {
    Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, 4> m(p_);
    if (p_ > 0) m(0) = 1;
    if (p_ > 1)
      for (int c = 0; c < 3; ++c) m(1 + c) = (double(point(c)) - shift_(c)) / scale_(c);
    return m;
  }

  void check_rcond() const {
    if (info_.rcond >= options_.min_rcond) return;
    std::ostringstream s;
    s << "RBF: the " << (info_.sparse ? "truncated sparse" : "dense") << " kernel system (" << n_ << " LR vertices, sigma = "
      << info_.sigma;
    if (p_) s << ", polynomial tail of degree " << options_.degree;
    s << ") is numerically singular: reciprocal condition " << info_.rcond << " < min_rcond = " << options_.min_rcond
      << "; lower sigma, add regularization, or check for duplicate LR vertices (and, with a tail, coplanar ones)";
    throw ArgumentError(s.str());
  }

  /// W[:, c] = K⁻¹ [ΔX^L[:, c]; 0] in place in the object's buffers (no allocation).
  void solve_component(const ConstPointsRef<S>& lr, int c) const {
    auto b = work_.col(c);
    auto x = weights_.col(c);
    const Index np = n_ + p_;
    for (Index i = 0; i < n_; ++i) b(i) = double(lr(i, c));
    for (Index i = n_; i < np; ++i) b(i) = 0;
    if (ldlt_) {  // P K Pᵀ = L D Lᵀ
      const auto& P = ldlt_->permutationP().indices();
      for (Index i = 0; i < np; ++i) x(P(i)) = b(i);
      ldlt_->matrixL().solveInPlace(x);
      x.array() /= d_.array();
      ldlt_->matrixU().solveInPlace(x);
      const auto& Pinv = ldlt_->permutationPinv().indices();
      for (Index i = 0; i < np; ++i) b(Pinv(i)) = x(i);
      x = b;
    } else {  // P K = L U
      const auto& P = lu_.permutationP().indices();
      for (Index i = 0; i < np; ++i) x(P(i)) = b(i);
      lu_.matrixLU().template triangularView<Eigen::UnitLower>().solveInPlace(x);
      lu_.matrixLU().template triangularView<Eigen::Upper>().solveInPlace(x);
    }
  }

  RBFOptions options_;
  RBFFitInfo info_;
  Index n_ = 0, m_ = 0, p_ = 0;
  Eigen::RowVector3d shift_ = Eigen::RowVector3d::Zero(), scale_ = Eigen::RowVector3d::Ones();
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  std::unique_ptr<SparseLdlt> ldlt_;
  Eigen::VectorXd d_;  ///< D of the sparse LDLᵀ
  Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> A_;  ///< M×N evaluation operator
  HrMatrix phi_hl_;                                                       ///< M×N Φ_HL (CSR)
  Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> poly_h_;  ///< M×P tail at HR vertices
  mutable Eigen::MatrixXd work_, weights_;                                // (N+P)×3 per-frame buffers
};

static_assert(assert_interpolator<RBF<double>>());
static_assert(assert_interpolator<RBF<float>>());

}  // namespace simsr::interp
