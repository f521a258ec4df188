#pragma once
/// \file
/// Dirichlet conditions of a quasistatic solve: the vertices whose positions are prescribed (bones,
/// a clamped end) and those positions. QuasistaticSolver::solve sets them and eliminates their
/// DOFs; BoneAttachments::boundary() is one way to make them.
///
///     physics::DirichletBoundary<> bc{select_vertices(V, is_clamped), clamped_positions};
///     newton.solve(exec::omp, x, bc, elastic, gravity);

#include "../core/types.hpp"

namespace simsr::physics {

/// Prescribed positions of constrained vertices: vertices (#B, sorted, unique) and targets.row(b)
/// the position of vertices[b] (#B×3, m). What the quasistatic solver consumes.
template <class S = Scalar>
struct DirichletBoundary {
  IndexVector vertices;
  Points<S> targets;

  Index size() const { return vertices.size(); }
};

}  // namespace simsr::physics
