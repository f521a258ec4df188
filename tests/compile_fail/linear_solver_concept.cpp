// Must NOT compile: QuasistaticSolver needs a physics::LinearSolver, and the error says so.
#include <simsr/physics/quasistatic.hpp>
struct NotASolver {
  using scalar_type = double;
};
int main() {
  simsr::physics::QuasistaticSolver<NotASolver> s(4, simsr::Tets(0, 4));
  (void)s;
}
