#pragma once
/// \file
/// Rigid motions x ↦ R x + t: the least-squares fit between two point sets (Kabsch / Umeyama
/// without scaling, through Eigen::umeyama) and the hinge a rotation turns about.
///
///     auto fit = simsr::fit_rigid_motion(exec::seq, teeth_rest, teeth_open);   // max_residual, rms_residual
///     auto jaw = simsr::hinge_of(fit.motion, teeth_rest.colwise().mean());     // axis, point, angle
///     Points<> moved = simsr::apply_rigid_motion(exec::omp, simsr::hinge_rotation(jaw, 0.1), X);
///
/// The face scenario reads its jaw hinge this way from data: the ICT kit's `jawOpen` moves the
/// lower teeth rigidly, and the fit gives the axis through the two jaw joints and the angle.

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <type_traits>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"

namespace simsr {

/// x ↦ R x + t with R a rotation (det +1).
template <class S = Scalar>
struct RigidMotion {
  Mat3<S> R = Mat3<S>::Identity();
  Vec3<S> t = Vec3<S>::Zero();

  Vec3<S> operator()(const Vec3<S>& x) const { return R * x + t; }
};

/// `m` applied to every row of X.
template <exec::HostPolicy P, class S>
Points<S> apply_rigid_motion(P policy, const RigidMotion<S>& m, const Points<S>& X) {
  Points<S> Y(X.rows(), 3);
  exec::parallel_for(policy, X.rows(), [&](Index i) { Y.row(i) = (m.R * X.row(i).transpose() + m.t).transpose(); });
  return Y;
}

/// A least-squares rigid fit and how far the points are from it.
template <class S = Scalar>
struct RigidFit {
  RigidMotion<S> motion;
  S max_residual = 0;  ///< max_i |R X_i + t − Y_i|
  S rms_residual = 0;  ///< sqrt(mean_i |R X_i + t − Y_i|²)
};

/// The rigid motion minimizing Σ|R X_i + t − Y_i|² (rows correspond). ShapeError for different
/// sizes, ArgumentError for fewer than 3 points, non-finite coordinates, or points on one line
/// (the rotation about that line is then undetermined).
template <exec::HostPolicy P, class S>
RigidFit<S> fit_rigid_motion(P policy, const Points<S>& X, const Points<S>& Y) {
  if (X.rows() != Y.rows()) throw ShapeError("fit_rigid_motion: Y (as many points as X)", {X.rows(), 3}, {Y.rows(), 3});
  if (X.rows() < 3) throw ArgumentError("fit_rigid_motion: needs at least 3 points, got " + std::to_string(X.rows()));
  if (!X.allFinite() || !Y.allFinite()) throw ArgumentError("fit_rigid_motion: non-finite coordinates");
  // Points on a line: the centred cloud's second singular value vanishes.
  const Points<S> Xc = X.rowwise() - X.colwise().mean();
  const Eigen::JacobiSVD<Eigen::Matrix<S, Eigen::Dynamic, 3>> svd(Xc);
  const auto sv = svd.singularValues();
  if (!(sv[1] > S(1e-9) * sv[0]))
    throw ArgumentError("fit_rigid_motion: the points lie on one line (singular values " + std::to_string(double(sv[0])) + ", " +
                        std::to_string(double(sv[1])) + "): the rotation about it is undetermined");
  const Eigen::Matrix<S, 4, 4> T = Eigen::umeyama(X.transpose(), Y.transpose(), false);
  RigidFit<S> fit;
  fit.motion.R = T.template topLeftCorner<3, 3>();
  fit.motion.t = T.template topRightCorner<3, 1>();
  const auto& m = fit.motion;
  fit.max_residual = exec::parallel_reduce(
      policy, X.rows(), S(0), [&](Index i) { return (m.R * X.row(i).transpose() + m.t - Y.row(i).transpose()).norm(); },
      [](S a, S b) { return std::max(a, b); });
  const S sq = exec::parallel_reduce(
      policy, X.rows(), S(0), [&](Index i) { return (m.R * X.row(i).transpose() + m.t - Y.row(i).transpose()).squaredNorm(); },
      std::plus<>{});
  fit.rms_residual = std::sqrt(sq / S(X.rows()));
  return fit;
}

/// A rotation seen as a hinge: turning by `angle` (radians, right-handed about `axis`) about the
/// line through `point` with direction `axis` (unit).
template <class S = Scalar>
struct Hinge {
  Vec3<S> point = Vec3<S>::Zero();
  Vec3<S> axis = Vec3<S>::UnitX();
  S angle = 0;
};

/// The hinge of a rigid motion: its rotation axis and angle, and the point of the axis closest to
/// `reference` (e.g. the centroid of the moved part). A rigid motion is a screw; the slide along
/// the axis, |t·axis|, must stay below `max_slide` (a hinge does not slide), otherwise
/// ArgumentError naming it (`max_slide` in the motion's length unit). ArgumentError also for a
/// rotation below 1e-6 rad (no axis).
template <class S>
Hinge<S> hinge_of(const RigidMotion<S>& m, const std::type_identity_t<Vec3<S>>& reference,
                  std::type_identity_t<S> max_slide = S(1e-2)) {
  const Eigen::AngleAxis<S> aa(m.R);
  if (!(std::abs(aa.angle()) > S(1e-6)))
    throw ArgumentError("hinge_of: the motion does not rotate (angle " + std::to_string(double(aa.angle())) + " rad): no hinge axis");
  Hinge<S> h;
  h.axis = aa.axis().normalized();
  h.angle = aa.angle();
  const S slide = m.t.dot(h.axis);
  if (std::abs(slide) > max_slide)
    throw ArgumentError("hinge_of: the motion slides " + std::to_string(double(slide)) + " along its axis (more than " +
                        std::to_string(double(max_slide)) + "): a screw, not a hinge");
  // Points p on the axis satisfy (I − R) p = t⊥ (t without its slide); I − R is singular along the
  // axis, so solve in the least-squares sense and move to the point closest to `reference`.
  const Vec3<S> t_perp = m.t - slide * h.axis;
  const Mat3<S> A = Mat3<S>::Identity() - m.R;
  const Vec3<S> p0 = A.jacobiSvd(Eigen::ComputeFullU | Eigen::ComputeFullV).solve(t_perp);
  h.point = p0 + (reference - p0).dot(h.axis) * h.axis;
  return h;
}

/// The rigid motion turning by `angle` (radians) about the hinge's axis (the hinge's own angle is
/// not used): x ↦ p + R(x − p).
template <class S>
RigidMotion<S> hinge_rotation(const Hinge<S>& h, std::type_identity_t<S> angle) {
  RigidMotion<S> m;
  m.R = Eigen::AngleAxis<S>(angle, h.axis).toRotationMatrix();
  m.t = h.point - m.R * h.point;
  return m;
}

}  // namespace simsr
