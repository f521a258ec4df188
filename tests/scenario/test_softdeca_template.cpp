// SoftDECA's layered template from the ICT kit: valid tets in both layers, cranium and jaw bones
// on the inner wrap, the skin and its expressions, the sizes reported.
#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <simsr/mesh/volume.hpp>
#include <simsr/scenario/softdeca/ict_template.hpp>

#include "kit_fixture.hpp"

using namespace simsr;

TEST_CASE("softdeca_template: the ICT head as skin, soft tissue, muscle and bone, every tet positive") {
  if (!test::have_ict_kit()) {
    SIMSR_MISSING("ICT kit not found in " << test::ict_kit_dir);
    return;
  }
  const auto& kit = test::ict_kit();
  const scenario::IctTemplate tpl = scenario::softdeca_template(exec::omp, kit, {});
  const auto& h = tpl.head;
  MESSAGE("SoftDECA template (layers " << h.layers << "): wrap " << h.wrap_vertices << " vertices, " << h.outer_triangles.rows()
                                       << " triangles; skin " << tpl.skin.size() << " vertices; soft tissue "
                                       << h.count(scenario::TissueLayer::soft_tissue) << " tets, muscle " << h.count(scenario::TissueLayer::muscle)
                                       << " tets; bone " << h.count(scenario::Bone::cranium) << " cranium + " << h.count(scenario::Bone::jaw)
                                       << " jaw + " << h.count(scenario::Bone::neck) << " neck vertices; march: " << tpl.bone_vertices << " bone, "
                                       << tpl.thin_vertices << " thin, " << tpl.deep_vertices << " deep; " << h.repaired_vertices << " thinned, "
                                       << h.collapsed_vertices << " pinched");
  CHECK(signed_volumes(exec::omp, h.mesh.V, h.mesh.T).minCoeff() > 0);
  CHECK(h.count(scenario::TissueLayer::muscle) == h.count(scenario::TissueLayer::soft_tissue));
  // every skin vertex of the kit is on the outer wrap, in metres; few columns pinched
  CHECK(tpl.skin.size() == kit.region("face").size() + kit.region("head_and_neck").size());
  CHECK(h.collapsed_vertices < h.wrap_vertices / 100);
  CHECK((h.mesh.V.row(tpl.skin[0]) - 0.01 * kit.neutral.V.row(tpl.kit_vertex[std::size_t(tpl.skin[0])])).norm() < 1e-12);
  // both bones exist and most of the inner wrap under the scalp is cranium
  CHECK(h.count(scenario::Bone::cranium) > h.wrap_vertices / 4);
  CHECK(h.count(scenario::Bone::jaw) > 100);
  CHECK(h.count(scenario::Bone::neck) > 0);
  // the flesh is thin on the scalp, thicker in the cheeks: between 3 mm and the 3 cm cap
  CHECK(h.thickness.minCoeff() >= 0);  // 0 where pinched
  CHECK(h.thickness.maxCoeff() <= 0.03 + 1e-12);
  // jawOpen moves the chin's skin down (−y) by centimetres
  VecX<> w = VecX<>::Zero(Index(tpl.expression_names.size()));
  w[Index(std::find(tpl.expression_names.begin(), tpl.expression_names.end(), "jawOpen") - tpl.expression_names.begin())] = 1;
  const Points<> open = tpl.expression(w);
  double lowest = 0;
  for (Index k = 0; k < tpl.skin.size(); ++k) lowest = std::min(lowest, open(k, 1) - h.mesh.V(tpl.skin[k], 1));
  CHECK(lowest < -0.01);
}
