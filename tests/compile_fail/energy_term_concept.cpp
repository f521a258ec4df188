// expect: is not a physics::EnergyTerm: it lacks add_hessian
// Must NOT compile: a term whose Hessian goes into a triplet list without a policy or a
// Definiteness (a form the solver used to accept) is not a physics::EnergyTerm, and
// QuasistaticSolver::solve (a library template constrained by the concept) says so in one sentence.
#include <simsr/physics/quasistatic.hpp>
struct OldHessianTerm {
  template <class P>
  double energy(P, const simsr::Points<double>&) const { return 0; }
  template <class P>
  void add_gradient(P, const simsr::Points<double>&, simsr::Points<double>&) const {}
  void add_hessian(const simsr::Points<double>&, simsr::physics::BlockTriplets<double>&) const {}
};
int main() {
  simsr::physics::QuasistaticSolver<> newton(4, simsr::Tets(0, 4));
  simsr::Points<double> x = simsr::Points<double>::Zero(4, 3);
  newton.solve(simsr::exec::seq, x, simsr::physics::DirichletBoundary<>{}, OldHessianTerm{});
}
