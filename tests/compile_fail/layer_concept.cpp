// expect: this type is not an nn::Layer: it lacks forward
// Must NOT compile: a layer whose forward takes the execution policy last (the convention before
// issue #10) is not an nn::Layer, and nn::Sequential (a library template checked by the concept)
// says so in one sentence.
#include <simsr/nn/sequential.hpp>
struct PolicyLastLayer {
  using scalar_type = float;
  template <class Policy>
  void forward(simsr::nn::Mode, const simsr::nn::ConstView<float>&, simsr::nn::Matrix<float>&, Policy) {}
  template <class Policy>
  void backward(const simsr::nn::ConstView<float>&, const simsr::nn::ConstView<float>&, const simsr::nn::ConstView<float>&,
                simsr::nn::Matrix<float>*, Policy) {}
  simsr::Index out_features(simsr::Index cols) const { return cols; }
};
int main() {
  simsr::nn::Sequential<PolicyLastLayer> chain{PolicyLastLayer{}};
  (void)chain;
}
