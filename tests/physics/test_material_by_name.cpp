#include "material_checks.hpp"

#include <simsr/core/error.hpp>
#include <simsr/physics/materials/by_name.hpp>

#include "../support/error_of.hpp"

#include <string>

using namespace simsr::physics;
using namespace simsr::physics::testing;

namespace {

/// ψ and P of the named material equal those of the one built directly, on many deformations
/// (inverted and near-degenerate ones included).
template <class M>
void check_same_material(const std::string& name, const MaterialParameters& p, const M& direct) {
  with_material(name, p, [&](const auto& m) {
    REQUIRE(std::is_same_v<std::remove_cvref_t<decltype(m)>, M>);
    for (const Sample& s : deformation_samples(40, false)) {
      CHECK(m.energy(s.F, {}) == direct.energy(s.F, {}));
      CHECK(m.stress(s.F, {}) == direct.stress(s.F, {}));
    }
  });
}

}  // namespace

TEST_CASE("with_material: each name builds its material from the named parameters") {
  MaterialParameters p;
  p.young = 3.5e5;
  p.poisson = 0.41;
  p.mu10 = 5e4;
  p.mu01 = 1e4;
  p.kappa = 9e5;
  p.inversion_threshold = 0.2;
  check_same_material("neo_hookean", p, NeoHookean<>::from_young_poisson(3.5e5, 0.41, 0.2));
  check_same_material("corotated", p, Corotated<>::from_young_poisson(3.5e5, 0.41));
  check_same_material("mooney_rivlin", p, MooneyRivlin<>(5e4, 1e4, 9e5, 0.2));
  CHECK(material_names().size() == 3);
  for (const auto& name : material_names()) CHECK_NOTHROW(with_material(name, MaterialParameters{}, [](const auto&) {}));
  // the value the visitor returns comes back, in the scalar asked for
  const double psi = with_material<float>("corotated", p, [](const auto& m) { return double(m.energy(simsr::Mat3<float>::Identity() * 1.1f, {})); });
  CHECK(psi == doctest::Approx(Corotated<float>::from_young_poisson(3.5e5f, 0.41f).energy(simsr::Mat3<float>::Identity() * 1.1f, {})));
}

TEST_CASE("with_material: unknown names and refused parameters are ArgumentErrors naming them") {
  auto message = [](const std::string& name, const MaterialParameters& p) {
    return simsr::test::typed_error_of<simsr::ArgumentError>([&] { with_material(name, p, [](const auto&) {}); });
  };
  CHECK(message("stvk", {}) == "unknown material 'stvk' (known: neo_hookean, corotated, mooney_rivlin)");
  CHECK(message("teran_muscle", {}).find("per-tet fibres") != std::string::npos);
  MaterialParameters p;
  p.poisson = 0.5;
  CHECK(message("neo_hookean", p).find("Poisson") != std::string::npos);
  p = {};
  p.kappa = -1;
  CHECK(message("mooney_rivlin", p).find("kappa") != std::string::npos);
}
