#pragma once
/// \file
/// The isotropic materials by name, for tools and bindings that take the material as a string
/// (the Python module's `material="neo_hookean"`): `with_material` builds the named material from
/// its parameters and hands it to a generic visitor, so the energy and the solve stay typed.
///
///     physics::MaterialParameters p;  p.young = 2e5;  p.poisson = 0.45;
///     physics::with_material("neo_hookean", p, [&](const auto& material) {
///       physics::ElasticEnergy elastic(mesh, material);   // ElasticEnergy<NeoHookean<>>
///     });
///
/// TeranMuscle is not here: its fibre directions and activations are per tet (use the C++ API).

#include <string>
#include <vector>

#include "../../core/error.hpp"
#include "corotated.hpp"
#include "mooney_rivlin.hpp"
#include "neo_hookean.hpp"

namespace simsr::physics {

/// Every parameter a material takes by name (each material reads its own; the checks are its
/// constructor's, which name the parameter).
struct MaterialParameters {
  double young = 1e5;    ///< neo_hookean, corotated: Young's modulus E (Pa)
  double poisson = 0.45; ///< neo_hookean, corotated: Poisson's ratio ν ∈ (−1, 0.5)
  double mu10 = 6e4;     ///< mooney_rivlin: μ10 (Pa; PhysBAM's face flesh)
  double mu01 = 2e4;     ///< mooney_rivlin: μ01 (Pa)
  double kappa = 1.6e6;  ///< mooney_rivlin: bulk modulus κ (Pa)
  double inversion_threshold = 0.1;  ///< neo_hookean, mooney_rivlin: J0, below which ψ is extended (inverted tets)
};

/// The names `with_material` knows.
inline const std::vector<std::string>& material_names() {
  static const std::vector<std::string> names{"neo_hookean", "corotated", "mooney_rivlin"};
  return names;
}

/// Builds the material `name` (scalar S) from `p` and returns `visit(material)`. ArgumentError for
/// an unknown name (listing the known ones) or a parameter the material refuses.
template <class S = Scalar, class Visit>
decltype(auto) with_material(const std::string& name, const MaterialParameters& p, Visit&& visit) {
  if (name == "neo_hookean") return visit(NeoHookean<S>::from_young_poisson(S(p.young), S(p.poisson), S(p.inversion_threshold)));
  if (name == "corotated") return visit(Corotated<S>::from_young_poisson(S(p.young), S(p.poisson)));
  if (name == "mooney_rivlin") return visit(MooneyRivlin<S>(S(p.mu10), S(p.mu01), S(p.kappa), S(p.inversion_threshold)));
  std::string known;
  for (const auto& n : material_names()) known += (known.empty() ? "" : ", ") + n;
  throw ArgumentError("unknown material '" + name + "' (known: " + known +
                      (name == "teran_muscle" ? "; teran_muscle needs per-tet fibres: use physics::TeranMuscle in C++)" : ")"));
}

}  // namespace simsr::physics
