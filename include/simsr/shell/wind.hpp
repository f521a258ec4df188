#pragma once
/// \file
/// Wind on a cloth surface (the DISK scene of Chen et al. 2023, issue #14): per triangle, the air's
/// velocity relative to the triangle's mean velocity has a normal part v_n = (w − v̄)·n̂, and the
/// pressure drag ½ ρ C_d A |v_n| v_n n̂ acts along the normal, a third on each corner (the
/// aerodynamic model of cloth simulators such as ARCSim, without the tangential friction).
///
///     shell::Air air{.velocity = Vec3<>(3, 0, 0)};
///     shell::wind_forces(exec::seq, x, v, F, air, f);   // f: #V×3 N, then VertexForces::set_forces

#include <cmath>
#include <string>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"

namespace simsr::shell {

/// The moving air: its velocity (m/s), density ρ (kg/m³) and drag coefficient C_d.
struct Air {
  Vec3<> velocity = Vec3<>::Zero();
  double density = 1.2;
  double drag = 1.0;
};

/// Per-vertex wind forces (#V×3, N) on the triangles F of a surface at positions x moving with
/// velocities v (both #V×3). Sequential (a scatter over the triangles; the policy is the
/// library's convention). ShapeError for mismatched sizes, MeshError for a face index out of
/// range, ArgumentError for a non-finite or negative air parameter.
template <exec::HostPolicy P, class S>
void wind_forces(P, const Points<S>& x, const Points<S>& v, const Tris& F, const Air& air, Points<S>& forces) {
  if (v.rows() != x.rows())
    throw ShapeError("wind_forces: velocities", {x.rows(), 3}, {v.rows(), v.cols()});
  if (!air.velocity.allFinite() || !(air.density >= 0) || !(air.drag >= 0) || !std::isfinite(air.density) || !std::isfinite(air.drag))
    throw ArgumentError("wind_forces: the air's velocity, density and drag must be finite, density and drag >= 0");
  forces.setZero(x.rows(), 3);
  const S half_rho_c = S(0.5 * air.density * air.drag);
  const Vec3<S> w = air.velocity.template cast<S>();
  for (Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k)
      if (F(f, k) < 0 || F(f, k) >= x.rows())
        throw MeshError("triangle", f, "wind_forces: vertex " + std::to_string(F(f, k)) + " outside [0, " + std::to_string(x.rows()) + ")");
    const Vec3<S> a = x.row(F(f, 0)).transpose(), b = x.row(F(f, 1)).transpose(), c = x.row(F(f, 2)).transpose();
    const Vec3<S> cross = (b - a).cross(c - a);
    const S twice_area = cross.norm();
    if (!(twice_area > S(0))) continue;  // a collapsed triangle has no normal and meets no air
    const Vec3<S> n = cross / twice_area;
    const Vec3<S> mean_v = (v.row(F(f, 0)) + v.row(F(f, 1)) + v.row(F(f, 2))).transpose() / S(3);
    const S vn = (w - mean_v).dot(n);
    const Vec3<S> third = half_rho_c * (S(0.5) * twice_area) * std::abs(vn) * vn * n / S(3);
    for (int k = 0; k < 3; ++k) forces.row(F(f, k)) += third.transpose();
  }
}

}  // namespace simsr::shell
