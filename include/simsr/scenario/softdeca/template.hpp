#pragma once
/// \file
/// A SoftDECA template: the layered head (layered_head.hpp) with its skin, the wrap vertices the
/// expressions and the simulation's outputs refer to, and the expressions as skin displacements.
/// Any layered head with a skin and expression displacements will do (the tests build one on a
/// sphere).

#include <string>
#include <vector>

#include <Eigen/Core>

#include "../../core/error.hpp"
#include "../../core/types.hpp"
#include "layered_head.hpp"

namespace simsr::scenario {

/// The template and its skin.
struct SoftDecaTemplate {
  LayeredHead head;                     ///< metres
  std::vector<VIndex> kit_vertex;       ///< per wrap vertex: the source mesh's vertex it came from (−1: none)
  IndexVector skin;                     ///< wrap vertices on the skin, increasing
  Tris skin_triangles;                  ///< the outer triangles on the skin (mesh vertex indices)
  std::vector<std::string> expression_names;
  Eigen::MatrixXd expression_deltas;    ///< E × 3·#skin: the expressions' displacements of the skin vertices (m), vertex-major

  /// The skin at expression weights w (E): rest + Σ_e w_e Δ_e, #skin×3 (m).
  Points<> expression(const VecX<>& weights) const {
    if (weights.size() != expression_deltas.rows()) throw ShapeError("SoftDecaTemplate::expression: weights", {expression_deltas.rows()}, {weights.size()});
    const VecX<> flat = expression_deltas.transpose() * weights;
    Points<> s(skin.size(), 3);
    for (Index k = 0; k < skin.size(); ++k) s.row(k) = head.mesh.V.row(skin[k]) + flat.segment<3>(3 * k).transpose();
    return s;
  }
};

}  // namespace simsr::scenario
