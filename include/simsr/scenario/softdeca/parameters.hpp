#pragma once
/// \file
/// SoftDECA's simulation parameters and their sampler (softdeca supplement §1), seeded and
/// reproducible per sample:
///
///   constraint weights   w_* ∈ [0.001, 100], log-uniform, each multiplying its term's reference
///                        stiffness (SoftDecaStiffness): strain of soft tissue and of muscle,
///                        volume, bending, target attraction, fitting distances
///   volume target        v ∈ [0.5, 1.5]  (E_vol = w (det F − v)²)
///   maximum strain       ε ∈ [0.7, 1.3]  (E_str's band [min(1, ε), max(1, ε)], strain_limit.hpp)
///   gravity              1–2 g, direction uniform on the sphere
///   skull                cranium and jaw scaled per axis, each factor ∈ [0.5, 1.5]
///   dynamics             α, β, γ ∈ [0, 2] (implicit_inertia.hpp: inertia, damping, momentum)
///
/// Sample i of seed s is drawn from its own generator, seeded by (s, i), so sample 17 is the same
/// whether 20 or 2000 samples are drawn and a resumed run draws exactly what it would have.
///
///     auto p = scenario::sample_softdeca_parameters(seed, i);
///     VecX<> in = p.to_vector();          // the surrogate's parameter input (SoftDecaParameters::names())

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../../core/error.hpp"
#include "../../core/types.hpp"

namespace simsr::scenario {

/// The reference stiffness each sampled weight multiplies (SI units). Chosen so that weight 1 is
/// soft facial tissue: strain moduli of a few kPa (fat ~1–3 kPa, relaxed muscle ~10 kPa), a
/// volume term of the same order, skin attraction that pulls with ~1 kPa per cm of deviation.
struct SoftDecaStiffness {
  double strain_soft_tissue = 3e3;  ///< Pa
  double strain_muscle = 1e4;       ///< Pa
  double volume = 1e4;              ///< Pa
  double bending = 1e-4;            ///< J
  double target = 1e5;              ///< J/m⁴ (per skin area, per squared metre of deviation)
  double distance = 1e5;            ///< J/m⁴
  double density = 1060;            ///< kg/m³ (soft tissue)
  double gravity = 9.81;            ///< m/s² (one g)
  nlohmann::ordered_json to_json() const {
    return {{"strain_soft_tissue", strain_soft_tissue}, {"strain_muscle", strain_muscle}, {"volume", volume}, {"bending", bending},
            {"target", target}, {"distance", distance}, {"density", density}, {"gravity", gravity}};
  }
};

/// The sampled ranges (the supplement's).
struct SoftDecaRanges {
  double weight_min = 1e-3, weight_max = 100;
  double volume_min = 0.5, volume_max = 1.5;
  double strain_min = 0.7, strain_max = 1.3;
  double gravity_min = 1, gravity_max = 2;  ///< in g
  double scale_min = 0.5, scale_max = 1.5;
  double dynamics_min = 0, dynamics_max = 2;
};

/// One sample of SoftDECA's parameters.
struct SoftDecaParameters {
  double w_strain_soft_tissue = 1, w_strain_muscle = 1, w_volume = 1, w_bending = 1, w_target = 1, w_distance = 1;
  double volume_target = 1;   ///< v
  double max_strain = 1;      ///< ε
  double gravity = 1;         ///< in g
  Vec3<> gravity_direction = Vec3<>(0, -1, 0);
  Vec3<> cranium_scale = Vec3<>::Ones(), jaw_scale = Vec3<>::Ones();
  double alpha = 0, beta = 0, gamma = 0;

  /// The names of to_vector()'s entries, in order (weights as log10).
  static std::vector<std::string> names() {
    return {"log10_w_strain_soft_tissue", "log10_w_strain_muscle", "log10_w_volume", "log10_w_bending", "log10_w_target", "log10_w_distance",
            "volume_target", "max_strain", "gravity_x", "gravity_y", "gravity_z", "cranium_scale_x", "cranium_scale_y", "cranium_scale_z",
            "jaw_scale_x", "jaw_scale_y", "jaw_scale_z", "alpha", "beta", "gamma"};
  }
  static constexpr Index size = 20;

  /// The parameters as one vector (weights as log10, gravity as the vector in g).
  VecX<> to_vector() const {
    VecX<> v(size);
    const Vec3<> g = gravity * gravity_direction;
    v << std::log10(w_strain_soft_tissue), std::log10(w_strain_muscle), std::log10(w_volume), std::log10(w_bending), std::log10(w_target),
        std::log10(w_distance), volume_target, max_strain, g.x(), g.y(), g.z(), cranium_scale.x(), cranium_scale.y(), cranium_scale.z(),
        jaw_scale.x(), jaw_scale.y(), jaw_scale.z(), alpha, beta, gamma;
    return v;
  }
  /// The inverse of to_vector(). ShapeError for another length, ArgumentError for a zero gravity vector.
  static SoftDecaParameters from_vector(const VecX<>& v) {
    if (v.size() != size) throw ShapeError("SoftDecaParameters::from_vector", {size}, {v.size()});
    SoftDecaParameters p;
    p.w_strain_soft_tissue = std::pow(10.0, v[0]);
    p.w_strain_muscle = std::pow(10.0, v[1]);
    p.w_volume = std::pow(10.0, v[2]);
    p.w_bending = std::pow(10.0, v[3]);
    p.w_target = std::pow(10.0, v[4]);
    p.w_distance = std::pow(10.0, v[5]);
    p.volume_target = v[6];
    p.max_strain = v[7];
    const Vec3<> g(v[8], v[9], v[10]);
    if (!(g.norm() > 0)) throw ArgumentError("SoftDecaParameters::from_vector: the gravity vector is zero");
    p.gravity = g.norm();
    p.gravity_direction = g / g.norm();
    p.cranium_scale = Vec3<>(v[11], v[12], v[13]);
    p.jaw_scale = Vec3<>(v[14], v[15], v[16]);
    p.alpha = v[17];
    p.beta = v[18];
    p.gamma = v[19];
    return p;
  }

  nlohmann::ordered_json to_json() const {
    nlohmann::ordered_json j;
    const auto names_ = names();
    const VecX<> v = to_vector();
    for (Index k = 0; k < size; ++k) j[names_[std::size_t(k)]] = v[k];
    return j;
  }
};

/// Sample `index` of the sampler seeded with `seed` (see the file comment).
inline SoftDecaParameters sample_softdeca_parameters(std::uint64_t seed, std::uint64_t index, const SoftDecaRanges& r = {}) {
  if (!(r.weight_min > 0 && r.weight_min <= r.weight_max) || !(r.volume_min > 0 && r.volume_min <= r.volume_max) ||
      !(r.strain_min > 0 && r.strain_min <= r.strain_max) || !(r.gravity_min >= 0 && r.gravity_min <= r.gravity_max) ||
      !(r.scale_min > 0 && r.scale_min <= r.scale_max) || !(r.dynamics_min >= 0 && r.dynamics_min <= r.dynamics_max))
    throw ArgumentError("sample_softdeca_parameters: every range needs 0 < min <= max (gravity and dynamics: 0 <= min <= max)");
  std::seed_seq seq{std::uint32_t(seed), std::uint32_t(seed >> 32), std::uint32_t(index), std::uint32_t(index >> 32), std::uint32_t(0x50f7deca)};
  std::mt19937_64 rng(seq);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  const auto log_uniform = [&](double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); };
  SoftDecaParameters p;
  p.w_strain_soft_tissue = log_uniform(r.weight_min, r.weight_max);
  p.w_strain_muscle = log_uniform(r.weight_min, r.weight_max);
  p.w_volume = log_uniform(r.weight_min, r.weight_max);
  p.w_bending = log_uniform(r.weight_min, r.weight_max);
  p.w_target = log_uniform(r.weight_min, r.weight_max);
  p.w_distance = log_uniform(r.weight_min, r.weight_max);
  p.volume_target = uniform(r.volume_min, r.volume_max);
  p.max_strain = uniform(r.strain_min, r.strain_max);
  p.gravity = uniform(r.gravity_min, r.gravity_max);
  // uniform direction: z uniform in [−1, 1], azimuth uniform (Archimedes)
  const double z = uniform(-1, 1), phi = uniform(0, 2 * 3.14159265358979323846), s = std::sqrt(std::max(0.0, 1 - z * z));
  p.gravity_direction = Vec3<>(s * std::cos(phi), s * std::sin(phi), z);
  for (int a = 0; a < 3; ++a) p.cranium_scale[a] = uniform(r.scale_min, r.scale_max);
  for (int a = 0; a < 3; ++a) p.jaw_scale[a] = uniform(r.scale_min, r.scale_max);
  p.alpha = uniform(r.dynamics_min, r.dynamics_max);
  p.beta = uniform(r.dynamics_min, r.dynamics_max);
  p.gamma = uniform(r.dynamics_min, r.dynamics_max);
  return p;
}

}  // namespace simsr::scenario
