// expect: is not a physics::LinearSolver: it lacks compute
// Must NOT compile: a solver whose compute and solve take no execution policy (the old calling
// convention) is not a physics::LinearSolver, and QuasistaticSolver (a library template
// constrained by the concept) says so in one sentence.
#include <simsr/physics/quasistatic.hpp>
struct PolicylessSolver {
  using scalar_type = double;
  void compute(const simsr::physics::SparseMatrix<double>&, std::uint64_t) {}
  simsr::physics::LinearSolveInfo solve(const simsr::VecX<double>&, simsr::VecX<double>&) { return {}; }
};
int main() {
  simsr::physics::QuasistaticSolver<PolicylessSolver> s(4, simsr::Tets(0, 4));
  (void)s;
}
