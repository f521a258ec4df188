#pragma once
/// \file
/// Two more rigid obstacles for physics::ObstacleContact (the thin-shell scenes of Chen et al.
/// 2023, issue #14): a rounded cylinder (a round table, a post) and a union of capsules (a
/// body-like obstacle: a torso and limbs as capsules).
///
///     physics::RoundedCylinder<> table(Vec3<>(0, 0, 0.7), Vec3<>::UnitZ(), 0.45, 0.02, 0.01);
///     physics::ObstacleContact contact(table, cloth_vertices, n, k);
///
/// Both are signed distances to convex (the cylinder) or unions of convex sets minus a rounding
/// radius, so they are C¹ outside the obstacle and their Hessians jump where the closest feature
/// changes (from the cap to the rim, from one capsule to another), as the Capsule's does.

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../../core/error.hpp"
#include "../../core/types.hpp"
#include "detail/checks.hpp"
#include "obstacle_contact.hpp"

namespace simsr::physics {

/// The points within `rounding` of a solid cylinder (centre c, unit axis u, radius a, half-height
/// h): a table top of radius a + rounding and thickness 2(h + rounding) with a rounded edge. With
/// s the distance from the axis, z = (x − c)·u, e_r the radial and t the tangential direction:
///
///     over a cap   (s ≤ a, |z| > h):  d = |z| − h − r,   ∇d = ±u,  ∇²d = 0
///     beside it    (s > a, |z| ≤ h):  d = s − a − r,     ∇d = e_r, ∇²d = t tᵀ / s
///     off the rim  (s > a, |z| > h):  q the closest point of the rim circle, ρ = ‖x − q‖,
///                                     d = ρ − r, ∇d = n = (x − q)/ρ,
///                                     ∇²d = (I − n nᵀ − (a/s) t tᵀ)/ρ
///     inside       (s ≤ a, |z| ≤ h):  d = −min(a − s, h − |z|) − r, the nearer face's normal
///
/// (the rim's Hessian: the closest point moves along the circle by a/s of x's tangential motion).
/// On the axis (s = 0) e_r is a fixed unit vector ⊥ u.
template <class S = Scalar>
class RoundedCylinder {
 public:
  using scalar_type = S;
  /// ArgumentError for a non-finite centre, a zero or non-finite axis, a radius or half-height
  /// not finite and ≥ 0, or a rounding not finite and > 0.
  RoundedCylinder(const Vec3<S>& centre, const Vec3<S>& axis, S radius, S half_height, S rounding)
      : a_(radius), h_(half_height), r_(rounding) {
    detail::require_nonnegative("RoundedCylinder: radius", radius);
    detail::require_nonnegative("RoundedCylinder: half-height", half_height);
    detail::require_positive("RoundedCylinder: rounding", rounding);
    detail::require_finite_vector("RoundedCylinder: axis", axis);
    if (!(axis.norm() > S(0))) throw ArgumentError("RoundedCylinder: axis is zero");
    u_ = axis.normalized();
    const Vec3<S> w = std::abs(u_.x()) < S(0.9) ? Vec3<S>::UnitX() : Vec3<S>::UnitY();
    fixed_radial_ = (w - w.dot(u_) * u_).normalized();
    set_centre(centre);
  }
  const Vec3<S>& centre() const { return c_; }
  const Vec3<S>& axis() const { return u_; }
  S radius() const { return a_; }
  S half_height() const { return h_; }
  S rounding() const { return r_; }
  /// Moves it (between frames).
  void set_centre(const Vec3<S>& c) {
    detail::require_finite_vector("RoundedCylinder: centre", c);
    c_ = c;
  }

  S distance(const Vec3<S>& x) const {
    const Local l = local(x);
    if (l.s <= a_ && std::abs(l.z) > h_) return std::abs(l.z) - h_ - r_;
    if (l.s > a_ && std::abs(l.z) <= h_) return l.s - a_ - r_;
    if (l.s > a_) return std::hypot(l.s - a_, std::abs(l.z) - h_) - r_;
    return -std::min(a_ - l.s, h_ - std::abs(l.z)) - r_;
  }
  Vec3<S> distance_gradient(const Vec3<S>& x) const {
    const Local l = local(x);
    const Vec3<S> up = l.z >= S(0) ? u_ : Vec3<S>(-u_);
    if (l.s <= a_ && std::abs(l.z) > h_) return up;
    if (l.s > a_ && std::abs(l.z) <= h_) return l.er;
    if (l.s > a_) {
      const S ds = l.s - a_, dz = std::abs(l.z) - h_, rho = std::hypot(ds, dz);
      return Vec3<S>((ds * l.er + dz * up) / rho);
    }
    return a_ - l.s < h_ - std::abs(l.z) ? l.er : up;
  }
  Mat3<S> distance_hessian(const Vec3<S>& x) const {
    const Local l = local(x);
    const bool beside = l.s > a_, over = std::abs(l.z) > h_;
    if (!beside || !(l.s > S(0))) return Mat3<S>::Zero();  // over a cap, inside, on the axis
    const Vec3<S> t = u_.cross(l.er);
    if (!over) return t * t.transpose() / l.s;
    const Vec3<S> up = l.z >= S(0) ? u_ : Vec3<S>(-u_);
    const S ds = l.s - a_, dz = std::abs(l.z) - h_, rho = std::hypot(ds, dz);
    const Vec3<S> n = (ds * l.er + dz * up) / rho;
    return (Mat3<S>::Identity() - n * n.transpose() - (a_ / l.s) * t * t.transpose()) / rho;
  }

 private:
  struct Local {
    S s, z;      ///< distance from the axis, height along it
    Vec3<S> er;  ///< radial unit vector
  };
  Local local(const Vec3<S>& x) const {
    const Vec3<S> v = x - c_;
    const S z = v.dot(u_);
    const Vec3<S> radial = v - z * u_;
    const S s = radial.norm();
    // at rounding level the radial direction means nothing: a fixed one ⊥ u
    const bool on_axis = !(s > S(64) * Eigen::NumTraits<S>::epsilon() * (v.norm() + a_ + h_));
    return {on_axis ? S(0) : s, z, on_axis ? fixed_radial_ : Vec3<S>(radial / s)};
  }

  Vec3<S> c_, u_, fixed_radial_;
  S a_, h_, r_;
};

/// A union of capsules (a body-like obstacle: torso, limbs, head): d is the smallest of their
/// signed distances, ∇d and ∇²d the closest one's (the first of equals). Each capsule moves on
/// its own (`capsule(k).set_ends`).
template <class S = Scalar>
class CapsuleUnion {
 public:
  using scalar_type = S;
  /// ArgumentError for no capsule.
  explicit CapsuleUnion(std::vector<Capsule<S>> capsules) : caps_(std::move(capsules)) {
    if (caps_.empty()) throw ArgumentError("CapsuleUnion: no capsule");
  }
  Index size() const { return Index(caps_.size()); }
  const Capsule<S>& capsule(Index k) const { return caps_.at(std::size_t(k)); }
  Capsule<S>& capsule(Index k) { return caps_.at(std::size_t(k)); }
  /// The capsule closest to x (the first of equals).
  Index closest(const Vec3<S>& x) const {
    Index best = 0;
    S d = caps_[0].distance(x);
    for (std::size_t k = 1; k < caps_.size(); ++k) {
      const S dk = caps_[k].distance(x);
      if (dk < d) d = dk, best = Index(k);
    }
    return best;
  }
  S distance(const Vec3<S>& x) const { return caps_[std::size_t(closest(x))].distance(x); }
  Vec3<S> distance_gradient(const Vec3<S>& x) const { return caps_[std::size_t(closest(x))].distance_gradient(x); }
  Mat3<S> distance_hessian(const Vec3<S>& x) const { return caps_[std::size_t(closest(x))].distance_hessian(x); }

 private:
  std::vector<Capsule<S>> caps_;
};

static_assert(Obstacle<RoundedCylinder<double>>);
static_assert(Obstacle<CapsuleUnion<double>>);

}  // namespace simsr::physics
