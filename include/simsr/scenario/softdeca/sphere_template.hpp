#pragma once
/// \file
/// A SoftDECA template on a sphere, standing in for a head in tests, benchmarks and examples (as
/// mesh/generators.hpp's solids do for meshes): radius 10 cm, flesh 1.5 cm deep, cranium bone
/// where the inner wrap lies above y = −3 cm, jaw below −6 cm (scaled about (0, −5, −2) cm), free
/// between; the whole outer wrap is skin, with two expressions: "bulge" (the front, +z, pushed out
/// by up to 1 cm) and "lift" (the top raised by up to 1 cm).
///
///     auto tpl = scenario::sphere_softdeca_template(exec::omp, 2, 1);   // icosphere level, layers

#include <algorithm>
#include <vector>

#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../../mesh/generators.hpp"
#include "layered_head.hpp"
#include "template.hpp"

namespace simsr::scenario {

/// The sphere template at icosphere `level` (2: 162 wrap vertices, 4: 2,562) with `layers` prisms
/// per shell (see the file comment).
template <exec::HostPolicy P>
SoftDecaTemplate sphere_softdeca_template(P policy, Index level, Index layers) {
  constexpr double radius = 0.1, flesh = 0.015;
  const TriMesh<> s = icosphere<double>(level, radius);
  const Index nv = s.V.rows();
  const Points<> inward = -s.V.rowwise().normalized();
  std::vector<Bone> bones(static_cast<std::size_t>(nv));
  for (Index i = 0; i < nv; ++i) bones[std::size_t(i)] = s.V(i, 1) > -0.03 ? Bone::cranium : s.V(i, 1) < -0.06 ? Bone::jaw : Bone::none;
  SoftDecaTemplate tpl;
  tpl.head = layered_head(policy, s, inward, VecX<>::Constant(nv, flesh), bones, {.layers = layers}, Vec3<>(0, -0.05, -0.02));
  tpl.skin.resize(nv);
  for (Index i = 0; i < nv; ++i) tpl.skin[i] = VIndex(i);
  tpl.skin_triangles = s.F;
  tpl.kit_vertex.assign(std::size_t(nv), -1);
  tpl.expression_names = {"bulge", "lift"};
  tpl.expression_deltas = Eigen::MatrixXd::Zero(2, 3 * nv);
  for (Index i = 0; i < nv; ++i) {
    const Vec3<> x = s.V.row(i).transpose() / radius;
    tpl.expression_deltas.row(0).segment<3>(3 * i) = 0.01 * std::max(0.0, x.z()) * x.transpose();
    tpl.expression_deltas(1, 3 * i + 1) = 0.01 * std::max(0.0, x.y());
  }
  return tpl;
}

}  // namespace simsr::scenario
