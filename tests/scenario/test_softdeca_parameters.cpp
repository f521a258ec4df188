// SoftDECA's parameter sampler: the supplement's ranges, log-uniform weights, uniform gravity
// directions, one generator per sample, and the surrogate's vector form.
#include <simsr/scenario/softdeca/parameters.hpp>

#include <doctest/doctest.h>

using namespace simsr;
using namespace simsr::scenario;

TEST_CASE("sample_softdeca_parameters: every draw inside the supplement's ranges; weights log-uniform, directions uniform") {
  const Index n = 4000;
  double log_mean = 0, dir_x = 0, dir_z = 0, v_mean = 0, eps_min = 9, eps_max = -9;
  for (Index i = 0; i < n; ++i) {
    const SoftDecaParameters p = sample_softdeca_parameters(42, std::uint64_t(i));
    for (double w : {p.w_strain_soft_tissue, p.w_strain_muscle, p.w_volume, p.w_bending, p.w_target, p.w_distance}) {
      CHECK(w >= 1e-3);
      CHECK(w <= 100);
      log_mean += std::log10(w) / (6.0 * double(n));
    }
    CHECK(p.volume_target >= 0.5);
    CHECK(p.volume_target <= 1.5);
    eps_min = std::min(eps_min, p.max_strain);
    eps_max = std::max(eps_max, p.max_strain);
    CHECK(p.gravity >= 1);
    CHECK(p.gravity <= 2);
    CHECK(p.gravity_direction.norm() == doctest::Approx(1).epsilon(1e-12));
    for (int a = 0; a < 3; ++a) {
      CHECK(p.cranium_scale[a] >= 0.5);
      CHECK(p.cranium_scale[a] <= 1.5);
      CHECK(p.jaw_scale[a] >= 0.5);
      CHECK(p.jaw_scale[a] <= 1.5);
    }
    for (double d : {p.alpha, p.beta, p.gamma}) {
      CHECK(d >= 0);
      CHECK(d <= 2);
    }
    dir_x += p.gravity_direction.x() / double(n);
    dir_z += p.gravity_direction.z() / double(n);
    v_mean += p.volume_target / double(n);
  }
  CHECK(eps_min < 0.71);
  CHECK(eps_max > 1.29);
  CHECK(log_mean == doctest::Approx(-0.5).epsilon(0.04));  // log10 uniform in [−3, 2]
  CHECK(std::abs(dir_x) < 0.05);
  CHECK(std::abs(dir_z) < 0.05);
  CHECK(v_mean == doctest::Approx(1.0).epsilon(0.02));
}

TEST_CASE("sample_softdeca_parameters: sample i depends on (seed, i) only; to_vector and from_vector invert each other") {
  const SoftDecaParameters a = sample_softdeca_parameters(7, 17), b = sample_softdeca_parameters(7, 17), c = sample_softdeca_parameters(8, 17),
                           d = sample_softdeca_parameters(7, 18);
  CHECK(a.to_vector() == b.to_vector());
  CHECK(a.to_vector() != c.to_vector());
  CHECK(a.to_vector() != d.to_vector());
  const VecX<> v = a.to_vector();
  CHECK(v.size() == SoftDecaParameters::size);
  CHECK(Index(SoftDecaParameters::names().size()) == SoftDecaParameters::size);
  CHECK((SoftDecaParameters::from_vector(v).to_vector() - v).cwiseAbs().maxCoeff() < 1e-12);
  CHECK_THROWS_AS(SoftDecaParameters::from_vector(v.head(5)), ShapeError);
  CHECK_THROWS_AS(sample_softdeca_parameters(1, 1, {.weight_min = 0}), ArgumentError);
  CHECK(a.to_json().size() == std::size_t(SoftDecaParameters::size));
}
