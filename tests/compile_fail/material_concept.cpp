// expect: is not a physics::Material: it lacks stress_derivative
// Must NOT compile: a type without stress_derivative is not a physics::Material, and ElasticEnergy
// (a library template constrained by the concept) says so in one sentence.
#include <simsr/mesh/generators.hpp>
#include <simsr/physics/elastic_energy.hpp>
struct HalfMaterial {
  using scalar_type = double;
  using Element = simsr::physics::NoElementData;
  double energy(const Eigen::Matrix3d&, const Element&) const { return 0; }
  Eigen::Matrix3d stress(const Eigen::Matrix3d&, const Element&) const { return Eigen::Matrix3d::Zero(); }
};
int main() {
  simsr::physics::ElasticEnergy<HalfMaterial> e(simsr::box_tet_mesh<double>(1, 1, 1), HalfMaterial{});
  (void)e;
}
