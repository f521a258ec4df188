#pragma once
/// \file
/// TS-ACAP: the temporally and spatially as-consistent-as-possible deformation features of a
/// triangle-mesh sequence (Chen et al. 2023 supplement §2.1; Gao et al. 2019), and the inverse map
/// back to positions.
///
/// Encoding a frame: per-vertex deformation gradients T_i by the one-ring fit (Eq. 1,
/// one_ring_fit.hpp); T_i = R_i S_i (polar_rotation.hpp); R_i's axis signs and 2π cycles made
/// consistent over the mesh and with the previous frame (Eq. 2–4, rotation_consistency.hpp). The
/// 9-d feature of vertex i is [Φ_i ω̂_i (3), S_i's upper triangle (6: s00 s01 s02 s11 s12 s22)]:
/// the rotation vector with the unwrapped angle Φ (so a vertex that turns through 3π over a
/// sequence reads 3π, not π) and the stretch.
///
/// Decoding: T_i = exp([Φω̂]×) S_i exactly, then positions from the cotangent-weighted Poisson
/// problem  min_p Σ_i Σ_{j∈N(i)} w_ij ‖(p_i − p_j) − T_i (q_i − q_j)‖², whose normal equations
/// Σ_j w_ij (p_i − p_j) = ½ Σ_j w_ij (T_i + T_j)(q_i − q_j) have the rest mesh's weighted graph
/// Laplacian for matrix: factored once per mesh (vertex 0 grounded), three back-substitutions a
/// frame. The translation the features do not carry is set by the caller's centroid.
///
/// Round trip: features → gradients is exact. positions → features → positions is exact (to
/// round-off) when every one-ring deforms by the same similarity (rigid motions with any angle,
/// over any number of turns, and uniform scaling); otherwise the Poisson solve returns the
/// least-squares positions of the fitted gradients, which differ from the input by an amount
/// tests/shell/test_ts_acap.cpp measures. No inverse of the 9-d features can be exact in
/// general: on a regular grid the cotangent-weighted fit of Eq. 1 is a central difference, blind
/// to a vertex-alternating in-plane perturbation.

#include <Eigen/SparseCholesky>
#include <cmath>
#include <numbers>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../mesh/topology.hpp"
#include "one_ring_fit.hpp"
#include "polar_rotation.hpp"
#include "rotation_consistency.hpp"

namespace simsr::shell {

/// Features per vertex.
inline constexpr Index ts_acap_feature_dim = 9;

/// #V×9 TS-ACAP features of one frame (row-major: a vertex's 9 values are contiguous).
template <class S = Scalar>
using TsAcapFeatures = Eigen::Matrix<S, Eigen::Dynamic, ts_acap_feature_dim, Eigen::RowMajor>;

struct TsAcapOptions {
  OneRingFitOptions fit;
  ConsistencyThresholds thresholds;
};

/// The previous frame of a sequence, as encode() needs it (empty before the first frame).
template <class S = Scalar>
struct TsAcapState {
  Points<S> axis;           ///< #V×3 oriented unit axes ω̂ = o ω
  VecX<S> angle;            ///< #V unwrapped angles Φ = 2πr + oθ
  VecX<S> principal_angle;  ///< #V principal angles θ ∈ [0, π] (Eq. 3's ε₂ test)
  bool empty() const { return axis.rows() == 0; }
};

/// What the integer steps of one frame did.
struct TsAcapFrameReport {
  ConsistencySolveStats axes, angles;
  Index flipped_axes = 0;    ///< vertices with o = −1
  Index wrapped_angles = 0;  ///< vertices with r ≠ 0
};

/// Moves each vertex's rotation vector (columns 0–2 of `f`) to the axis–angle form of the same
/// rotation nearest `reference`'s at that vertex. The forms of a rotation by t about u are
/// u(t + 2πk), k ∈ ℤ (a negative factor is the opposite axis, Eq. 2's sign), and every one gives
/// the same T_i; the nearest to ρ_ref is k = round((u·ρ_ref − t) / 2π), a closed form per vertex
/// (the identity, t = 0, takes u along ρ_ref). Why: two meshes whose rotations were lifted by
/// their own integer problems (Eq. 2–4) can differ by 2π at a vertex where the two chose
/// differently, though their rotations are close; a residual between them (the fine features
/// minus the subdivided coarse mesh's) then jumps by 2π there, which a network must learn as a
/// spike. Lifted this way the residual holds only the rotation between them. The stretch columns
/// are untouched. Returns how many vertices moved; ShapeError for another vertex count,
/// ArgumentError for a non-finite entry.
template <class S>
Index lift_rotations_toward(TsAcapFeatures<S>& f, const TsAcapFeatures<S>& reference) {
  if (f.rows() != reference.rows()) throw ShapeError("lift_rotations_toward: reference features", {f.rows(), ts_acap_feature_dim}, {reference.rows(), reference.cols()});
  if (!f.allFinite() || !reference.allFinite()) throw ArgumentError("lift_rotations_toward: features contain NaN or Inf");
  constexpr double two_pi = 2 * std::numbers::pi;
  Index moved = 0;
  for (Index i = 0; i < f.rows(); ++i) {
    const Vec3<double> rho = f.row(i).template head<3>().transpose().template cast<double>();
    const Vec3<double> ref = reference.row(i).template head<3>().transpose().template cast<double>();
    double t = rho.norm();
    Vec3<double> u;
    if (t > 0) {
      u = rho / t;
    } else if (ref.norm() > 0) {
      u = ref.normalized();
    } else {
      continue;  // both the identity's zero form
    }
    const double k = std::round((u.dot(ref) - t) / two_pi);
    if (k == 0) continue;
    t += two_pi * k;
    f.row(i).template head<3>() = (u * t).transpose().template cast<S>();
    ++moved;
  }
  return moved;
}

template <class S = Scalar>
class TsAcap {
 public:
  /// rest #V×3 and F #F×3 of a connected triangle mesh: the reference C₀ (or D₀) of the paper.
  /// Throws what OneRingFit throws, and MeshError for a mesh in more than one piece.
  template <exec::HostPolicy P>
  TsAcap(P policy, const Points<S>& rest, const Tris& F, TsAcapOptions options = {})
      : options_(options), fit_(policy, rest, F, options.fit), graph_(consistency_graph(unique_edges(F), rest.rows())) {
    const Components C = connected_components(F, rest.rows());
    if (C.count != 1)
      throw MeshError("triangle mesh", -1, "TsAcap needs one connected piece, got " + std::to_string(C.count));
    const Adjacency& A = fit_.adjacency();
    const Index n = rest.rows();
    std::vector<Eigen::Triplet<S, Index>> trip;
    for (Index i = 1; i < n; ++i)
      for (Index k = A.offsets[i]; k < A.offsets[i + 1]; ++k) {
        const Index j = A.neighbors[k];
        const S w = fit_.weights()[k];
        trip.emplace_back(i - 1, i - 1, w);
        if (j != 0) trip.emplace_back(i - 1, j - 1, -w);
      }
    Eigen::SparseMatrix<S> K(n - 1, n - 1);
    K.setFromTriplets(trip.begin(), trip.end());
    if (n > 1) {
      poisson_.compute(K);
      if (poisson_.info() != Eigen::Success)
        throw MeshError("triangle mesh", -1, "TsAcap: the weighted Laplacian does not factor (zero edge weights?)");
    }
  }

  Index num_vertices() const { return fit_.num_vertices(); }
  const OneRingFit<S>& fit() const { return fit_; }
  const Edges& edges() const { return graph_.edges; }

  /// Features of frame V (#V×3) of a sequence whose previous frame `state` holds (empty: V is
  /// the first frame); `state` becomes V's. `report` (optional) receives what the integer steps did.
  template <exec::HostPolicy P>
  TsAcapFeatures<S> encode(P policy, const Points<S>& V, TsAcapState<S>& state, TsAcapFrameReport* report = nullptr) const {
    const Index n = num_vertices();
    const std::vector<Mat3<S>> gradients = fit_.gradients(policy, V);
    Points<S> axis(n, 3);
    VecX<S> theta(n);
    TsAcapFeatures<S> out(n, ts_acap_feature_dim);
    exec::parallel_for(policy, n, [&](Index i) {
      const PolarParts<S> pp = polar_decomposition(gradients[static_cast<std::size_t>(i)]);
      const AxisAngle<S> aa = principal_axis_angle(pp.R);
      axis.row(i) = aa.axis.transpose();
      theta[i] = aa.angle;
      const Mat3<S>& St = pp.stretch;
      out.row(i).template tail<6>() << St(0, 0), St(0, 1), St(0, 2), St(1, 1), St(1, 2), St(2, 2);
    });
    const bool first = state.empty();
    if (!first && (state.axis.rows() != n || state.angle.size() != n || state.principal_angle.size() != n))
      throw ShapeError("TsAcap::encode: state (previous frame)", {n}, {state.axis.rows()});
    const ConsistencyThresholds& th = options_.thresholds;
    AxisSignProblem signs;
    signs.graph = &graph_;
    signs.fix_first = first;
    signs.edge_score.resize(static_cast<std::size_t>(graph_.edges.rows()));
    signs.vertex_score.assign(static_cast<std::size_t>(n), 0);
    for (Index e = 0; e < graph_.edges.rows(); ++e) {
      const Index a = graph_.edges(e, 0), b = graph_.edges(e, 1);
      signs.edge_score[e] = orientation_score(double(axis.row(a).dot(axis.row(b))), double(theta[a]), double(theta[b]), th);
    }
    if (!first)
      for (Index i = 0; i < n; ++i)
        signs.vertex_score[i] = orientation_score(double(axis.row(i).dot(state.axis.row(i))), double(theta[i]),
                                                  double(state.principal_angle[i]), th);
    TsAcapFrameReport rep;
    const std::vector<int> o = solve_axis_signs(signs, &rep.axes);
    AngleCycleProblem cycles;
    cycles.graph = &graph_;
    cycles.fix_first = first;
    cycles.phi.resize(static_cast<std::size_t>(n));
    for (Index i = 0; i < n; ++i) cycles.phi[i] = o[i] * double(theta[i]);
    if (!first) cycles.previous = std::vector<double>(state.angle.data(), state.angle.data() + n);
    const std::vector<int> r = solve_angle_cycles(cycles, &rep.angles);
    constexpr double two_pi = 2 * std::numbers::pi;
    state.axis.resize(n, 3);
    state.angle.resize(n);
    state.principal_angle = theta;
    for (Index i = 0; i < n; ++i) {
      const Vec3<S> w = S(o[i]) * Vec3<S>(axis.row(i).transpose());
      const S Phi = S(two_pi * r[i] + cycles.phi[i]);
      state.axis.row(i) = w.transpose();
      state.angle[i] = Phi;
      out.row(i).template head<3>() = (Phi * w).transpose();
      rep.flipped_axes += o[i] < 0;
      rep.wrapped_angles += r[i] != 0;
    }
    if (report) *report = rep;
    return out;
  }

  /// Features of every frame of a sequence, frame 0 first (its own first frame).
  template <exec::HostPolicy P>
  std::vector<TsAcapFeatures<S>> encode_sequence(P policy, const std::vector<Points<S>>& frames) const {
    TsAcapState<S> state;
    std::vector<TsAcapFeatures<S>> out;
    out.reserve(frames.size());
    for (const Points<S>& V : frames) out.push_back(encode(policy, V, state));
    return out;
  }

  /// T_i = exp([ρ_i]×) S_i from #V×9 features (exact).
  template <exec::HostPolicy P>
  std::vector<Mat3<S>> gradients_from_features(P policy, const TsAcapFeatures<S>& f) const {
    check_features(f);
    std::vector<Mat3<S>> T(static_cast<std::size_t>(f.rows()));
    exec::parallel_for(policy, f.rows(), [&](Index i) {
      Mat3<S> St;
      St << f(i, 3), f(i, 4), f(i, 5), f(i, 4), f(i, 6), f(i, 7), f(i, 5), f(i, 7), f(i, 8);
      T[static_cast<std::size_t>(i)] = rotation_from_vector(Vec3<S>(f(i, 0), f(i, 1), f(i, 2))) * St;
    });
    return T;
  }

  /// Positions from #V×9 features: the prefactored Poisson solve, translated so that their mean
  /// is `centroid`. Throws ShapeError for a wrong feature count, ArgumentError for NaN/Inf.
  template <exec::HostPolicy P>
  Points<S> decode(P policy, const TsAcapFeatures<S>& f, const Vec3<S>& centroid) const {
    const std::vector<Mat3<S>> T = gradients_from_features(policy, f);
    return positions_from_gradients(policy, T, centroid);
  }

  /// The Poisson solve of the file comment for given gradients (#V of them).
  template <exec::HostPolicy P>
  Points<S> positions_from_gradients(P policy, const std::vector<Mat3<S>>& T, const Vec3<S>& centroid) const {
    const Index n = num_vertices();
    const Eigen::Matrix<S, Eigen::Dynamic, 3> b = poisson_rhs(policy, T);
    Points<S> p(n, 3);
    p.row(0).setZero();
    if (n > 1) {
      const Eigen::Matrix<S, Eigen::Dynamic, 3> x = poisson_.solve(b.bottomRows(n - 1));
      p.bottomRows(n - 1) = x;
    }
    const Vec3<S> shift = centroid - Vec3<S>(p.colwise().mean().transpose());
    p.rowwise() += shift.transpose();
    return p;
  }

  /// Fixes `anchors` (vertex indices, at least one) for decode_anchored: the Laplacian of the
  /// other vertices, factored once. Where a scene pins vertices (a sheet's corners, a tablecloth's
  /// centre), their known positions replace the centroid, which is what a coarse mesh predicts
  /// worst (the fine cloth hangs differently as a whole). MeshError for an index outside the mesh
  /// or a repeated one.
  void set_anchors(const IndexVector& anchors) {
    const Index n = num_vertices();
    if (anchors.size() == 0) throw ArgumentError("TsAcap::set_anchors: no anchor");
    free_index_.assign(static_cast<std::size_t>(n), 0);
    for (Index a = 0; a < anchors.size(); ++a) {
      const Index v = anchors[a];
      if (v < 0 || v >= n) throw MeshError("vertex", v, "TsAcap::set_anchors: outside the mesh of " + std::to_string(n) + " vertices");
      if (free_index_[std::size_t(v)] < 0) throw MeshError("vertex", v, "TsAcap::set_anchors: anchored twice");
      free_index_[std::size_t(v)] = -1 - a;
    }
    Index m = 0;
    for (auto& k : free_index_)
      if (k >= 0) k = m++;
    anchors_ = anchors;
    const Adjacency& A = fit_.adjacency();
    std::vector<Eigen::Triplet<S, Index>> trip;
    for (Index i = 0; i < n; ++i) {
      const Index r = free_index_[std::size_t(i)];
      if (r < 0) continue;
      for (Index k = A.offsets[i]; k < A.offsets[i + 1]; ++k) {
        const Index c = free_index_[std::size_t(A.neighbors[k])];
        trip.emplace_back(r, r, fit_.weights()[k]);
        if (c >= 0) trip.emplace_back(r, c, -fit_.weights()[k]);
      }
    }
    Eigen::SparseMatrix<S> K(m, m);
    K.setFromTriplets(trip.begin(), trip.end());
    if (m > 0) {
      anchored_.compute(K);
      if (anchored_.info() != Eigen::Success)
        throw MeshError("triangle mesh", -1, "TsAcap::set_anchors: the weighted Laplacian of the free vertices does not factor");
    }
  }
  const IndexVector& anchors() const { return anchors_; }

  /// Positions from #V×9 features with the anchors of set_anchors at `anchor_positions` (one row
  /// per anchor, in set_anchors' order): the Poisson problem of the file comment with those
  /// vertices fixed. ArgumentError before set_anchors; ShapeError for a wrong row count.
  template <exec::HostPolicy P>
  Points<S> decode_anchored(P policy, const TsAcapFeatures<S>& f, const Points<S>& anchor_positions) const {
    if (anchors_.size() == 0) throw ArgumentError("TsAcap::decode_anchored: call set_anchors first");
    if (anchor_positions.rows() != anchors_.size())
      throw ShapeError("TsAcap::decode_anchored: anchor positions", {anchors_.size(), 3}, {anchor_positions.rows(), 3});
    const std::vector<Mat3<S>> T = gradients_from_features(policy, f);
    const Index n = num_vertices(), m = n - anchors_.size();
    const Eigen::Matrix<S, Eigen::Dynamic, 3> b = poisson_rhs(policy, T);
    const Adjacency& A = fit_.adjacency();
    Eigen::Matrix<S, Eigen::Dynamic, 3> bf(m, 3);
    for (Index i = 0; i < n; ++i) {
      const Index r = free_index_[std::size_t(i)];
      if (r < 0) continue;
      bf.row(r) = b.row(i);
      for (Index k = A.offsets[i]; k < A.offsets[i + 1]; ++k) {
        const Index c = free_index_[std::size_t(A.neighbors[k])];
        if (c < 0) bf.row(r) += fit_.weights()[k] * anchor_positions.row(-1 - c);
      }
    }
    Points<S> p(n, 3);
    const Eigen::Matrix<S, Eigen::Dynamic, 3> x = m > 0 ? Eigen::Matrix<S, Eigen::Dynamic, 3>(anchored_.solve(bf)) : bf;
    for (Index i = 0; i < n; ++i) {
      const Index r = free_index_[std::size_t(i)];
      if (r >= 0) p.row(i) = x.row(r);
      else p.row(i) = anchor_positions.row(-1 - r);
    }
    return p;
  }

 private:
  /// b_i = ½ Σ_j w_ij (T_i + T_j)(q_i − q_j), the right-hand side of the file comment's equations.
  template <exec::HostPolicy P>
  Eigen::Matrix<S, Eigen::Dynamic, 3> poisson_rhs(P policy, const std::vector<Mat3<S>>& T) const {
    const Index n = num_vertices();
    if (static_cast<Index>(T.size()) != n) throw ShapeError("TsAcap: gradients", {n}, {static_cast<std::int64_t>(T.size())});
    const Adjacency& A = fit_.adjacency();
    const Points<S>& q = fit_.rest();
    Eigen::Matrix<S, Eigen::Dynamic, 3> b(n, 3);
    exec::parallel_for(policy, n, [&](Index i) {
      Vec3<S> bi = Vec3<S>::Zero();
      for (Index k = A.offsets[i]; k < A.offsets[i + 1]; ++k) {
        const Index j = A.neighbors[k];
        bi += S(0.5) * fit_.weights()[k] * (T[static_cast<std::size_t>(i)] + T[static_cast<std::size_t>(j)]) *
              (simsr::detail::point(q, i) - simsr::detail::point(q, j));
      }
      b.row(i) = bi.transpose();
    });
    return b;
  }

  void check_features(const TsAcapFeatures<S>& f) const {
    if (f.rows() != num_vertices())
      throw ShapeError("TsAcap: features", {num_vertices(), ts_acap_feature_dim}, {f.rows(), f.cols()});
    if (!f.allFinite()) throw ArgumentError("TsAcap: features contain NaN or Inf");
  }

  TsAcapOptions options_;
  OneRingFit<S> fit_;
  ConsistencyGraph graph_;  // the integer steps' graph, built once
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<S>> poisson_;
  IndexVector anchors_;
  std::vector<Index> free_index_;  // per vertex: its row among the free vertices, or −1 − (its anchor number)
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<S>> anchored_;
};

}  // namespace simsr::shell
