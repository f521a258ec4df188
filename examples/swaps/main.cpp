// swaps: simsr's four swap points, each a few lines and one type (or one argument) away from the
// other choice, on small inputs made here. One JSON line per swap on stdout:
//
//   interpolator  the same function template with Embedded, then IDW     (interp::Interpolator)
//   material      the same sagging beam with neo-Hookean, then Mooney–Rivlin (physics::Material)
//   layer         an MLP with LeakyReLU, then with Sine between its Linears  (nn::Layer)
//   policy        the same neighbourhoods under exec::seq, then exec::omp    (bitwise equal)
//
//   swaps
#include <simsr/data/network_neighborhoods.hpp>
#include <simsr/interp/interp.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/nn/nn.hpp>
#include <simsr/physics/physics.hpp>

#include <nlohmann/json.hpp>

#include <exception>
#include <iostream>

using namespace simsr;

namespace {

// --- interpolator: any interp::Interpolator; the problem's HR sphere moves with its LR box ------
template <interp::Interpolator Method>
double held_out_error(Method method, interp::UpsamplingProblem<> problem) {
  interp::prepare(exec::omp, method, problem, 20);  // fit (+ the §3.2 neighbourhoods where it needs them)
  const Mat3<> A{{1.05, 0.1, 0}, {0, 0.95, 0.05}, {0.02, 0, 1.1}};  // an affine motion of both meshes
  const Points<> lr_disp = problem.lr.V * A.transpose() - problem.lr.V, truth = problem.hr.V * A.transpose() - problem.hr.V;
  Points<> hr_disp(problem.num_hr(), 3);
  method.apply(exec::omp, lr_disp, hr_disp);
  return (hr_disp - truth).rowwise().norm().mean();
}

// --- material: any physics::Material in the same elastic energy; a beam clamped at x = 0 ---------
template <class Material>
double tip_sag(const Material& material) {
  const TetMesh<> beam = box_tet_mesh<double>(10, 1, 1, Vec3<>(0, 0, 0), Vec3<>(1, 0.1, 0.1));
  physics::ElasticEnergy<Material> flesh(beam, material);
  physics::Gravity<> gravity(beam, 1000.0, Vec3<>(0, 0, -9.81));
  physics::BoneAttachments<> clamp(beam.V);
  clamp.add_bone("wall", physics::select_vertices(beam.V, [](const Vec3<>& p) { return p.x() <= 1e-9; }));
  physics::QuasistaticSolver<physics::SparseCholesky<>> newton(beam.num_vertices(), beam.T);
  Points<> x = beam.V;
  newton.solve(exec::omp, x, clamp.boundary(), flesh, gravity);
  return -(x.col(2) - beam.V.col(2)).minCoeff();
}

// --- layer: nn::Sequential's middle layer is a template argument ----------------------------------
template <template <class> class Activation>
float mlp_output_norm(Activation<float> activation) {
  nn::ParameterStore<float> store;
  nn::Rng rng(7);
  nn::Sequential<nn::Linear<float>, Activation<float>, nn::Linear<float>> mlp{
      nn::Linear<float>(store, "fc.0", 3, 16, rng), std::move(activation), nn::Linear<float>(store, "fc.2", 16, 3, rng)};
  const nn::Matrix<float> in = nn::Matrix<float>::Constant(4, 3, 0.5f);
  nn::Matrix<float> out;
  mlp.forward(exec::omp, nn::Mode::eval, in, out);
  return out.norm();
}

}  // namespace

int main() try {
  interp::UpsamplingProblem<> problem{box_tet_mesh<double>(4, 4, 4, Vec3<>(-1, -1, -1), Vec3<>(1, 1, 1)), icosphere<double>(2, 0.8), {}, {}};
  nlohmann::ordered_json j;

  j = {{"swap", "interpolator"},
       {"embedded_mean_error", held_out_error(interp::Embedded<>(), problem)},  // exact: barycentric weights reproduce affine motion
       {"idw_mean_error", held_out_error(interp::IDW<>(), problem)}};
  std::cout << j.dump() << '\n';

  j = {{"swap", "material"},
       {"neo_hookean_tip_sag_m", tip_sag(physics::NeoHookean<>::from_young_poisson(2e7, 0.3))},
       // about the same stiffness: E = 2e7 Pa, ν = 0.3 is μ = 2 (μ10 + μ01) = 7.7e6 Pa, κ = 1.67e7 Pa
       {"mooney_rivlin_tip_sag_m", tip_sag(physics::MooneyRivlin<>(3e6, 0.85e6, 1.67e7))}};
  std::cout << j.dump() << '\n';

  j = {{"swap", "layer"}, {"leaky_relu_output_norm", mlp_output_norm<nn::LeakyReLU>(nn::LeakyReLU<float>(0.2f))},
       {"sine_output_norm", mlp_output_norm<nn::Sine>(nn::Sine<float>(30.0f))}};
  std::cout << j.dump() << '\n';

  const auto seq = data::compute_network_neighborhoods(exec::seq, problem.lr, problem.hr, 8, 8);
  const auto omp = data::compute_network_neighborhoods(exec::omp, problem.lr, problem.hr, 8, 8);
  j = {{"swap", "policy"},
       {"same_neighbourhoods", seq.upsampling.indices == omp.upsampling.indices && seq.upsampling.distances == omp.upsampling.distances &&
                                   seq.lr_graph == omp.lr_graph}};
  std::cout << j.dump() << '\n';
  return 0;
} catch (const std::exception& e) {
  std::cerr << "swaps: " << e.what() << '\n';
  return 1;
}
