#pragma once
/// \file
/// How much each point of the head follows the jaw: the skinning weight of the core paper's
/// linear-blend-skinned rest pose (§4) and of the bones, read from the kit's own `jawOpen`.
///
/// Kit vertex i with jawOpen displacement d_i and rigid jaw displacement r_i = R x_i + t − x_i
/// (the hinge's full rotation) gets w_i = clamp(d_i·r_i / max(|r_i|², r_min²), 0, 1): 1 for the
/// lower teeth and the chin, 0 for the cranium's skin, in between in the cheeks. Points that are
/// no kit vertex (the skull, lattice nodes) take the Gaussian-weighted mean of their k nearest
/// kit vertices' weights, one smooth function of position, so the HR and the LR mesh at the same
/// point get the same weight.
///
///     scenario::JawWeights jw(kit, rest_positions, jaw.hinge);
///     VecX<> w = jw.at(exec::omp, skull.surface.V);

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../../mesh/rigid_motion.hpp"
#include "../../neighbors/kd_tree.hpp"
#include "ict_kit.hpp"

namespace simsr::scenario {

/// Options of JawWeights (lengths in the kit's unit, cm).
struct JawWeightOptions {
  double min_lever = 0.2;  ///< r_min: below this jaw displacement the ratio is taken against r_min
  double sigma = 1.0;      ///< Gaussian width of the field
  Index neighbours = 24;   ///< kit vertices averaged per query point
  /// The parts whose vertices define the field (the eyeballs and the sockets' far side follow no jaw).
  std::vector<std::string> parts{"face", "head_and_neck", "mouth_socket", "gums_and_tongue", "teeth_upper", "teeth_lower"};
};

/// The per-vertex weights and the field through them (see the file comment).
class JawWeights {
 public:
  /// `positions`: the kit's vertices where the field is wanted (the rest pose); the hinge with its
  /// full jawOpen angle, in the same frame.
  JawWeights(const IctKit& kit, const Points<>& positions, const Hinge<>& hinge, const std::string& opening = "jawOpen",
             JawWeightOptions options = {})
      : opt_(std::move(options)) {
    if (positions.rows() != kit.num_vertices()) throw ShapeError("JawWeights: positions", {kit.num_vertices(), 3}, {positions.rows(), 3});
    if (!(opt_.sigma > 0) || !(opt_.min_lever > 0) || opt_.neighbours < 1) throw ArgumentError("JawWeights: sigma, min_lever and neighbours must be > 0");
    const Points<> d = kit.expression(opening);
    const Mat3<> R = Eigen::AngleAxisd(hinge.angle, hinge.axis.normalized()).toRotationMatrix();
    kit_weight_.setZero(kit.num_vertices());
    for (Index v = 0; v < kit.num_vertices(); ++v) {
      const Vec3<> x = kit.neutral.V.row(v).transpose();
      const Vec3<> r = R * (x - hinge.point) + hinge.point - x;
      kit_weight_[v] = std::clamp(d.row(v).dot(r.transpose()) / std::max(r.squaredNorm(), opt_.min_lever * opt_.min_lever), 0.0, 1.0);
    }
    std::vector<Index> ids;
    for (const auto& name : opt_.parts) {
      const VertexRange r = kit.region(name);
      for (Index v = r.first; v <= r.last; ++v) ids.push_back(v);
    }
    points_.resize(Index(ids.size()), 3);
    values_.resize(Index(ids.size()));
    for (std::size_t k = 0; k < ids.size(); ++k) {
      points_.row(Index(k)) = positions.row(ids[k]);
      values_[Index(k)] = kit_weight_[ids[k]];
    }
    tree_.build(points_);
  }

  /// w_i of every kit vertex (from the expression, no smoothing).
  const VecX<>& kit_weights() const { return kit_weight_; }

  /// The field at the rows of X (#X×3).
  template <exec::HostPolicy P>
  VecX<> at(P policy, const Points<>& X) const {
    const Index k = std::min(opt_.neighbours, points_.rows());
    neighbors::KnnResult<double> knn;
    tree_.query_into(policy, X, k, knn);
    VecX<> w(X.rows());
    exec::parallel_for(policy, X.rows(), [&](Index q) {
      double num = 0, den = 0;
      for (Index j = 0; j < k; ++j) {
        const Index i = knn.indices(q, j);
        const double d2 = (points_.row(i) - X.row(q)).squaredNorm();
        const double g = std::exp(-0.5 * d2 / (opt_.sigma * opt_.sigma)) + 1e-300;
        num += g * values_[i];
        den += g;
      }
      w[q] = num / den;
    });
    return w;
  }

 private:
  JawWeightOptions opt_;
  VecX<> kit_weight_;
  Points<> points_;
  VecX<> values_;
  neighbors::KdTree<double> tree_;
};

}  // namespace simsr::scenario
