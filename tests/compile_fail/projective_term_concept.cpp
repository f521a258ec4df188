// expect: is not a physics::ProjectiveTerm: it lacks add_global_matrix
// A term the Newton solver takes but the local-global solver cannot (no constant matrix).
#include <simsr/mesh/generators.hpp>
#include <simsr/physics/local_global.hpp>

struct NewtonOnly {
  template <class P>
  double energy(P, const simsr::Points<>&) const { return 0; }
  template <class P>
  void add_gradient(P, const simsr::Points<>&, simsr::Points<>&) const {}
  template <class P>
  void add_hessian(P, const simsr::Points<>&, simsr::physics::BlockHessian<>&, simsr::physics::Definiteness) const {}
};

int main() {
  const auto mesh = simsr::box_tet_mesh<double>(1, 1, 1);
  simsr::physics::LocalGlobalSolver<> solver(mesh.num_vertices(), mesh.T);
  simsr::Points<> x = mesh.V;
  solver.solve(simsr::exec::seq, x, {}, NewtonOnly{});
}
