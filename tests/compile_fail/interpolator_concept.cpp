// expect: this type is not an interp::Interpolator
// Must NOT compile: a method whose apply takes no policy is not an interp::Interpolator, and Ridge's
// base (a library template constrained by the concept) says so in one sentence.
#include <simsr/interp/ridge.hpp>
struct NoPolicyApply {
  using scalar_type = double;
  template <class P>
  void fit(P, simsr::interp::UpsamplingProblem<double>&) {}
  void apply(const simsr::Points<double>&, simsr::Points<double>&) const {}
  simsr::Index num_lr() const { return 0; }
  simsr::Index num_hr() const { return 0; }
};
int main() {
  simsr::interp::Ridge<double, NoPolicyApply> ridge;
  (void)ridge;
}
