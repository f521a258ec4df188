#pragma once
/// \file
/// Given forces on vertices as a potential: E(x) = −Σ_i f_i·x_i (J), gradient −f, Hessian 0. The
/// forces are set between steps (wind computed from the last step's velocities, a hand pulling),
/// so an implicit step treats them as constant over the step, as ARCSim treats its wind.
///
///     physics::VertexForces<> wind(n);
///     wind.set_forces(shell::wind_forces(x, v, F, air));   // N per vertex, each step
///     solver.solve(exec::omp, x, pins, membrane, bending, gravity, inertia, wind);

#include <string>
#include <utility>

#include <Eigen/Core>

#include "../../core/error.hpp"
#include "../../core/types.hpp"
#include "../energy_term.hpp"
#include "detail/checks.hpp"

namespace simsr::physics {

/// Constant per-vertex forces f (#V×3, N) as the linear potential −Σ f_i·x_i.
template <class S = Scalar>
class VertexForces {
 public:
  using scalar_type = S;
  /// Zero forces on `num_vertices` vertices.
  explicit VertexForces(Index num_vertices) : f_(Points<S>::Zero(num_vertices, 3)) {
    if (num_vertices < 0) throw ArgumentError("VertexForces: negative vertex count");
  }
  Index num_vertices() const { return f_.rows(); }
  const Points<S>& forces() const { return f_; }
  /// ShapeError for another vertex count, ArgumentError for a non-finite force.
  void set_forces(const Points<S>& f) {
    if (f.rows() != f_.rows() || f.cols() != 3)
      throw ShapeError("VertexForces: forces", {f_.rows(), 3}, {f.rows(), f.cols()});
    if (!f.allFinite()) throw ArgumentError("VertexForces: a force is not finite");
    f_ = f;  // same size: a copy into the existing buffer
  }

  /// −Σ f_i·x_i (J).
  template <exec::HostPolicy P>
  S energy(P, const Points<S>& x) const {
    detail::require_positions("VertexForces: x", x, num_vertices());
    return -(f_.array() * x.array()).sum();
  }
  /// g −= f (N).
  template <exec::HostPolicy P>
  void add_gradient(P, const Points<S>& x, Points<S>& g) const {
    detail::require_positions("VertexForces: x", x, num_vertices());
    detail::require_positions("VertexForces: gradient", g, num_vertices());
    g -= f_;
  }
  /// Adds nothing: the energy is linear.
  template <exec::HostPolicy P>
  void add_hessian(P, const Points<S>& x, BlockHessian<S>&, Definiteness) const {
    detail::require_positions("VertexForces: x", x, num_vertices());
  }
  /// Adds nothing to the local–global matrix either.
  template <exec::HostPolicy P>
  void add_global_matrix(P, BlockHessian<S>&) const {}

 private:
  Points<S> f_;
};

static_assert(assert_energy_term<VertexForces<double>, double>());

}  // namespace simsr::physics
