#pragma once
/// \file
/// Penalty contact of designated vertices against analytic rigid obstacles (SPEC §3: a rigid
/// sphere pushed into the cheek, §5.3 of Park et al. 2023). With d_i the obstacle's signed
/// distance at vertex i (negative inside) and k_i the vertex's penalty stiffness (N/m):
///
///     E(x) = Σ_i k_i/2 min(d(x_i), 0)²                        (J)
///
///     physics::ObstacleContact contact(physics::Sphere<>(centre, 0.02), surface_vertices, V.rows(), 1e4);
///     contact.obstacle().set_centre(centre + frame * step);   // move it each frame
///
/// Stiffness is per vertex in N/m; for resolution-independent contact pass k_i = κ A_i (κ in
/// N/m³, A_i the vertex areas of simsr::vertex_areas), as the track springs do. The energy is
/// C¹ (its Hessian jumps at d = 0). Obstacles are a concept: any type with signed distance,
/// its gradient and its Hessian works.

#include <algorithm>
#include <cmath>
#include <concepts>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "../../core/types.hpp"
#include "../energy_term.hpp"
#include "detail/checks.hpp"

namespace simsr::physics {

namespace detail {
/// The symmetric part of A with its negative eigenvalues clamped to 0 (kept exactly when PSD up
/// to rounding): the contact blocks' definiteness fix.
template <class S>
Mat3<S> project_psd3(const Mat3<S>& A) {
  const Mat3<S> sym = (A + A.transpose()) / S(2);
  Eigen::SelfAdjointEigenSolver<Mat3<S>> es;
  es.computeDirect(sym);
  const S tol = S(64) * Eigen::NumTraits<S>::epsilon() * es.eigenvalues().cwiseAbs().maxCoeff();
  if (es.eigenvalues().minCoeff() >= -tol) return sym;  // PSD up to rounding: keep the exact block
  return es.eigenvectors() * es.eigenvalues().cwiseMax(S(0)).asDiagonal() * es.eigenvectors().transpose();
}

/// The penalty's profile against the signed distance d (m) for stiffness k (N/m) and onset
/// depth δ (m, ≥ 0): its value f, slope f' = df/dd and curvature f'' = d²f/dd², all 0 for d ≥ 0.
///
///     δ = 0:            f = k/2 d²,                     f' = k d,          f'' = k
///     δ > 0, −δ < d < 0: f = −k d³/(6δ),                f' = −k d²/(2δ),   f'' = −k d/δ
///            d ≤ −δ:     f = k/2 d² + kδ/2 d + kδ²/6,   f' = k d + kδ/2,   f'' = k
///
/// δ = 0 is C¹: the curvature jumps from 0 to k as a point enters, so Newton's quadratic model
/// is wrong on both sides of every point on the surface, and a contact set that changes from
/// iteration to iteration (cloth sliding over an edge) stalls it. δ > 0 ramps the curvature
/// linearly over the first δ of depth (C², the pieces' values, slopes and curvatures meet at
/// 0 and −δ); the price is δ/2 more penetration under the same load.
template <class S>
struct PenaltyProfile {
  S value, slope, curvature;
};
template <class S>
PenaltyProfile<S> penalty_profile(S d, S k, S onset) {
  if (!(d < S(0))) return {S(0), S(0), S(0)};
  if (onset == S(0)) return {k / S(2) * d * d, k * d, k};
  if (d > -onset) return {-k * d * d * d / (S(6) * onset), -k * d * d / (S(2) * onset), -k * d / onset};
  return {k / S(2) * d * d + k * onset / S(2) * d + k * onset * onset / S(6), k * d + k * onset / S(2), k};
}

/// One point p's penalty against obstacle o with stiffness k and onset δ (penalty_profile), the
/// class comment's formulas shared by ObstacleContact (p a vertex) and EmbeddedObstacleContact
/// (p an embedded point): the energy f(d), and for d < 0 the derivative f'(d) ∇d and the
/// PSD-projected block f''(d) ∇d ∇dᵀ + f'(d) ∇²d (δ = 0: k (∇d ∇dᵀ + d ∇²d)). The last two
/// return false (and leave their output) where d ≥ 0.
template <class O, class S>
S obstacle_penalty_energy(const O& o, const Vec3<S>& p, S k, S onset = S(0)) {
  return penalty_profile(S(o.distance(p)), k, onset).value;
}
template <class O, class S>
bool obstacle_penalty_force(const O& o, const Vec3<S>& p, S k, Vec3<S>& f, S onset = S(0)) {
  const S d = o.distance(p);
  if (!(d < S(0))) return false;
  f = penalty_profile(d, k, onset).slope * o.distance_gradient(p);
  return true;
}
template <class O, class S>
bool obstacle_penalty_block(const O& o, const Vec3<S>& p, S k, Mat3<S>& B, S onset = S(0)) {
  const S d = o.distance(p);
  if (!(d < S(0))) return false;
  const Vec3<S> n = o.distance_gradient(p);
  if (onset == S(0)) {  // the δ = 0 block as it always was, to the last bit
    B = k * project_psd3(Mat3<S>(n * n.transpose() + d * o.distance_hessian(p)));
    return true;
  }
  const PenaltyProfile<S> f = penalty_profile(d, k, onset);
  B = project_psd3(Mat3<S>(f.curvature * n * n.transpose() + f.slope * o.distance_hessian(p)));
  return true;
}
}  // namespace detail

/// A rigid obstacle: signed distance d(x) (m, negative inside), its gradient ∇d (unit outward
/// normal where d is smooth) and its Hessian ∇²d (1/m), all total functions of x ∈ ℝ³.
template <class O, class S = typename O::scalar_type>
concept Obstacle = requires(const O& o, const Vec3<S>& x) {
  { o.distance(x) } -> std::convertible_to<S>;
  { o.distance_gradient(x) } -> std::convertible_to<Vec3<S>>;
  { o.distance_hessian(x) } -> std::convertible_to<Mat3<S>>;
};

/// The half-space behind a plane through `point` with normal `normal` (normalized here; the
/// free side is where it points): d = (x − p)·n, ∇d = n, ∇²d = 0.
template <class S = Scalar>
class Plane {
 public:
  using scalar_type = S;
  /// ArgumentError for a zero or non-finite normal or a non-finite point.
  Plane(const Vec3<S>& point, const Vec3<S>& normal) : p_(point) {
    detail::require_finite_vector("Plane: point", point);
    set_normal(normal);
  }
  const Vec3<S>& point() const { return p_; }
  const Vec3<S>& normal() const { return n_; }
  void set_point(const Vec3<S>& p) {
    detail::require_finite_vector("Plane: point", p);
    p_ = p;
  }
  void set_normal(const Vec3<S>& n) {
    detail::require_finite_vector("Plane: normal", n);
    if (!(n.norm() > S(0))) throw ArgumentError("Plane: normal is zero");
    n_ = n.normalized();
  }
  S distance(const Vec3<S>& x) const { return (x - p_).dot(n_); }
  Vec3<S> distance_gradient(const Vec3<S>&) const { return n_; }
  Mat3<S> distance_hessian(const Vec3<S>&) const { return Mat3<S>::Zero(); }

 private:
  Vec3<S> p_, n_;
};

/// A solid ball: d = ‖x − c‖ − r, ∇d = n = (x − c)/‖x − c‖, ∇²d = (I − n nᵀ)/‖x − c‖. At the
/// centre itself (where n is undefined) n = +z and ∇²d = 0.
template <class S = Scalar>
class Sphere {
 public:
  using scalar_type = S;
  /// ArgumentError for a non-finite centre or a radius not finite and > 0.
  Sphere(const Vec3<S>& centre, S radius) : r_(radius) {
    detail::require_positive("Sphere: radius", radius);
    set_centre(centre);
  }
  const Vec3<S>& centre() const { return c_; }
  S radius() const { return r_; }
  void set_centre(const Vec3<S>& c) {
    detail::require_finite_vector("Sphere: centre", c);
    c_ = c;
  }
  S distance(const Vec3<S>& x) const { return (x - c_).norm() - r_; }
  Vec3<S> distance_gradient(const Vec3<S>& x) const {
    const S l = (x - c_).norm();
    return l > S(0) ? Vec3<S>((x - c_) / l) : Vec3<S>::UnitZ();
  }
  Mat3<S> distance_hessian(const Vec3<S>& x) const {
    const S l = (x - c_).norm();
    if (!(l > S(0))) return Mat3<S>::Zero();
    const Vec3<S> n = (x - c_) / l;
    return (Mat3<S>::Identity() - n * n.transpose()) / l;
  }

 private:
  Vec3<S> c_;
  S r_;
};

/// A capsule: the points within `radius` of the segment [a, b] (a pole, a limb). With q the
/// closest point of the segment and ρ = ‖x − q‖: d = ρ − r, ∇d = n = (x − q)/ρ, and
/// ∇²d = (I − u uᵀ − n nᵀ)/ρ beside the segment (u its direction: the distance to a line) or
/// (I − n nᵀ)/ρ beyond an end (the distance to a point). On the axis itself (ρ = 0) n is a fixed
/// unit vector ⊥ u and ∇²d = 0. a = b is a sphere.
template <class S = Scalar>
class Capsule {
 public:
  using scalar_type = S;
  /// ArgumentError for non-finite ends or a radius not finite and > 0.
  Capsule(const Vec3<S>& a, const Vec3<S>& b, S radius) : r_(radius) {
    detail::require_positive("Capsule: radius", radius);
    set_ends(a, b);
  }
  const Vec3<S>& a() const { return a_; }
  const Vec3<S>& b() const { return b_; }
  S radius() const { return r_; }
  /// Moves the segment (between frames).
  void set_ends(const Vec3<S>& a, const Vec3<S>& b) {
    detail::require_finite_vector("Capsule: end a", a);
    detail::require_finite_vector("Capsule: end b", b);
    a_ = a, b_ = b;
  }
  S distance(const Vec3<S>& x) const { return offset(x).norm() - r_; }
  Vec3<S> distance_gradient(const Vec3<S>& x) const {
    const Vec3<S> v = offset(x);
    const S l = v.norm();
    return on_axis(x, l) ? off_axis() : Vec3<S>(v / l);
  }
  Mat3<S> distance_hessian(const Vec3<S>& x) const {
    const Vec3<S> v = offset(x);
    const S l = v.norm();
    if (on_axis(x, l)) return Mat3<S>::Zero();
    const Vec3<S> n = v / l;
    Mat3<S> H = Mat3<S>::Identity() - n * n.transpose();
    const S t = parameter(x);
    if (t > S(0) && t < S(1)) {  // beside the segment: no curvature along it
      const Vec3<S> u = (b_ - a_).normalized();
      H -= u * u.transpose();
    }
    return H / l;
  }

 private:
  S parameter(const Vec3<S>& x) const {
    const Vec3<S> ab = b_ - a_;
    const S len2 = ab.squaredNorm();
    return len2 > S(0) ? std::clamp((x - a_).dot(ab) / len2, S(0), S(1)) : S(0);
  }
  /// x minus its closest point: beside the segment the part of x − a normal to it (exactly ⊥ to
  /// the axis up to rounding), beyond an end x minus that end.
  Vec3<S> offset(const Vec3<S>& x) const {
    const S t = parameter(x);
    if (t <= S(0)) return x - a_;
    if (t >= S(1)) return x - b_;
    const Vec3<S> u = (b_ - a_).normalized(), w = x - a_;
    return w - w.dot(u) * u;
  }
  /// ρ at rounding level: the direction of x − q means nothing there.
  bool on_axis(const Vec3<S>& x, S l) const {
    return !(l > S(64) * Eigen::NumTraits<S>::epsilon() * ((x - a_).norm() + (b_ - a_).norm()));
  }
  Vec3<S> off_axis() const {
    const Vec3<S> ab = b_ - a_;
    if (!(ab.norm() > S(0))) return Vec3<S>::UnitZ();
    const Vec3<S> u = ab.normalized();
    const Vec3<S> w = std::abs(u.x()) < S(0.9) ? Vec3<S>::UnitX() : Vec3<S>::UnitY();
    return (w - w.dot(u) * u).normalized();
  }

  Vec3<S> a_, b_;
  S r_;
};

/// Penalty contact of `vertices` (indices into x) against one obstacle O.
///
/// Hessian per penetrating vertex (onset 0): the 3×3 block k (∇d ∇dᵀ + d ∇²d), exact when positive
/// semi-definite, otherwise with its negative eigenvalues clamped to 0 (PSD projection). For a
/// Plane this is exactly k n nᵀ; for a Sphere d < 0 makes the tangential part k d/‖x − c‖ (I − n nᵀ)
/// negative, so the projection keeps k n nᵀ (the penalty does not resist sliding on the sphere).
template <class O, class S = typename O::scalar_type>
  requires Obstacle<O, S>
class ObstacleContact {
 public:
  using scalar_type = S;

  /// Same stiffness k (N/m, finite, ≥ 0) on every vertex. ArgumentError for a vertex outside
  /// [0, num_vertices) or a bad k.
  ObstacleContact(O obstacle, IndexVector vertices, Index num_vertices, S k)
      : ObstacleContact(std::move(obstacle), vertices, num_vertices, VecX<S>::Constant(vertices.size(), k)) {
    detail::require_nonnegative("ObstacleContact: stiffness", k);
  }
  /// Per-vertex stiffness (#vertices, N/m; e.g. κ × vertex area). ShapeError for a size mismatch.
  ObstacleContact(O obstacle, IndexVector vertices, Index num_vertices, VecX<S> k)
      : o_(std::move(obstacle)), v_(std::move(vertices)), n_(num_vertices), k_(std::move(k)) {
    detail::require_vertex_indices("ObstacleContact: vertices", v_, n_);
    detail::require_nonnegative_each("ObstacleContact: stiffness", k_, v_.size());
  }

  O& obstacle() { return o_; }  ///< to move the obstacle between frames
  const O& obstacle() const { return o_; }
  /// The depth δ (m) over which the penalty's stiffness ramps from 0 to k (detail::penalty_profile):
  /// 0 (the default) is the C¹ quadratic, δ > 0 makes the energy C². ArgumentError for δ not
  /// finite and ≥ 0.
  void set_onset(S onset) {
    detail::require_nonnegative("ObstacleContact: onset", onset);
    onset_ = onset;
  }
  S onset() const { return onset_; }
  const IndexVector& vertices() const { return v_; }
  const VecX<S>& stiffness() const { return k_; }
  Index num_vertices() const { return n_; }

  /// Positions in `vertices()` (not vertex ids) of the penetrating vertices (d < 0), ascending.
  std::vector<Index> active(const Points<S>& x) const {
    detail::require_positions("ObstacleContact: x", x, n_);
    std::vector<Index> a;
    for (Index i = 0; i < v_.size(); ++i)
      if (o_.distance(pos(x, i)) < S(0)) a.push_back(i);
    return a;
  }

  template <exec::HostPolicy P>
  S energy(P, const Points<S>& x) const {
    detail::require_positions("ObstacleContact: x", x, n_);
    S e = S(0);
    for (Index i = 0; i < v_.size(); ++i) e += detail::obstacle_penalty_energy(o_, pos(x, i), k_[i], onset_);
    return e;
  }

  template <exec::HostPolicy P>
  void add_gradient(P, const Points<S>& x, Points<S>& g) const {
    detail::require_positions("ObstacleContact: x", x, n_);
    detail::require_positions("ObstacleContact: gradient", g, n_);
    Vec3<S> f;
    for (Index i = 0; i < v_.size(); ++i)
      if (detail::obstacle_penalty_force(o_, pos(x, i), k_[i], f, onset_)) g.row(v_[i]) += f.transpose();
  }

  /// The PSD-projected blocks of the class comment, for both Definiteness values.
  template <exec::HostPolicy P>
  void add_hessian(P, const Points<S>& x, BlockHessian<S>& H, Definiteness) const {
    detail::require_positions("ObstacleContact: x", x, n_);
    Mat3<S> B;
    for (Index i = 0; i < v_.size(); ++i)
      if (detail::obstacle_penalty_block(o_, pos(x, i), k_[i], B, onset_)) H.add(v_[i], v_[i], B);
  }

  /// The local–global solver's constant matrix: k_i I for every vertex that may touch, whether it
  /// does or not. A stand-in (the true Hessian switches on and off with the contact set): the
  /// solver takes the exact gradient and line-searches, so its fixed point is still the energy's
  /// minimum, and the matrix stays factored while the contact set changes.
  template <exec::HostPolicy P>
  void add_global_matrix(P, BlockHessian<S>& L) const {
    for (Index i = 0; i < v_.size(); ++i) L.add(v_[i], v_[i], Mat3<S>(k_[i] * Mat3<S>::Identity()));
  }

 private:
  Vec3<S> pos(const Points<S>& x, Index i) const { return x.row(v_[i]).transpose(); }

  O o_;
  IndexVector v_;
  Index n_;
  VecX<S> k_;
  S onset_ = S(0);
};

/// `ObstacleContact c(Sphere<>(...), vertices, n, k)` with k a scalar or any vector expression.
template <class O, class K>
ObstacleContact(O, IndexVector, Index, K) -> ObstacleContact<O>;

static_assert(Obstacle<Plane<double>> && Obstacle<Sphere<double>> && Obstacle<Capsule<double>>);
static_assert(assert_energy_term<ObstacleContact<Sphere<double>>, double>());

}  // namespace simsr::physics
