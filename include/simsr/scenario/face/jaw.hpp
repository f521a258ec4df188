#pragma once
/// \file
/// The jaw hinge from data (core paper §4: a mandible that rotates about the axis through the two
/// jaw joints). The ICT kit's `jawOpen` moves the lower teeth rigidly and leaves the upper teeth
/// where they are; the least-squares rigid motion of the lower teeth is a rotation of 25.3° about
/// the left–right axis, and that rotation's axis is the hinge.
///
///     auto jaw = simsr::scenario::jaw_from_kit(exec::seq, kit);   // jaw.hinge: point, axis, angle
///     auto open = simsr::hinge_rotation(jaw.hinge, 0.1 * jaw.hinge.angle);   // a tenth of jawOpen

#include <cmath>
#include <string>

#include "../../core/error.hpp"
#include "../../mesh/rigid_motion.hpp"
#include "ict_kit.hpp"

namespace simsr::scenario {

/// The hinge and how well the data supports it.
struct JawFromData {
  Hinge<> hinge;          ///< axis oriented so that a positive angle opens the mouth; angle: the expression's own
  RigidFit<> lower_fit;   ///< the rigid fit of the lower teeth (residuals in cm)
  double upper_motion = 0;  ///< largest displacement of an upper tooth vertex under the expression (cm)
};

/// Reads the hinge from expression `opening` (default jawOpen) of the kit: ArgumentError when the
/// lower teeth do not move rigidly (max residual above `max_residual` cm), when the upper teeth
/// move more than `max_upper_motion` cm, or when the motion is no hinge (see hinge_of).
template <exec::HostPolicy P>
JawFromData jaw_from_kit(P policy, const IctKit& kit, const std::string& opening = "jawOpen", double max_residual = 0.1,
                         double max_upper_motion = 0.05) {
  const Points<> d = kit.expression(opening);
  const VertexRange lower = kit.region("teeth_lower"), upper = kit.region("teeth_upper");
  const Points<> X = kit.neutral.V.middleRows(lower.first, lower.size());
  const Points<> Y = X + d.middleRows(lower.first, lower.size());
  JawFromData jaw;
  jaw.lower_fit = fit_rigid_motion(policy, X, Y);
  if (!(jaw.lower_fit.max_residual <= max_residual))
    throw ArgumentError("jaw_from_kit: under '" + opening + "' the lower teeth do not move rigidly (max residual " +
                        std::to_string(jaw.lower_fit.max_residual) + " cm > " + std::to_string(max_residual) + ")");
  jaw.upper_motion = d.middleRows(upper.first, upper.size()).rowwise().norm().maxCoeff();
  if (!(jaw.upper_motion <= max_upper_motion))
    throw ArgumentError("jaw_from_kit: under '" + opening + "' the upper teeth move " + std::to_string(jaw.upper_motion) +
                        " cm (> " + std::to_string(max_upper_motion) + "): the cranium would not be fixed");
  const Vec3<> centroid = X.colwise().mean().transpose();
  jaw.hinge = hinge_of(jaw.lower_fit.motion, centroid, 0.01 * std::max(1.0, jaw.lower_fit.motion.t.norm()));
  if (jaw.hinge.angle < 0) {  // the same rotation, written with a positive opening angle
    jaw.hinge.axis = -jaw.hinge.axis;
    jaw.hinge.angle = -jaw.hinge.angle;
  }
  return jaw;
}

}  // namespace simsr::scenario
