#pragma once
/// \file
/// The paper's "Embedded" baseline (§5, Table 2/Fig. 6): the HR rest surface is embedded in the
/// LR rest tets by barycentric weights, and every frame's HR displacement is the weighted sum of
/// the LR displacements of the 4 vertices of its tet. Reproduces any affine displacement field
/// exactly (also at extrapolated points outside the LR mesh).
///
///     interp::Embedded<> e;  e.fit(exec::omp, problem);      // problem.lr: TetMesh, problem.hr: TriMesh
///     e.apply(exec::omp, lr_displacement, hr_displacement);  // N×3 → M×3, no allocation

#include <string>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../discretize/embedding.hpp"
#include "concepts.hpp"
#include "detail/embedded_apply.hpp"
#include "problem.hpp"

namespace simsr::interp {

/// Barycentric-embedding interpolator (S = double or float). Satisfies interp::Interpolator; apply
/// is const and may run concurrently.
template <class S = Scalar>
class Embedded {
 public:
  using scalar_type = S;
  /// fit reads only the rest shapes.
  static constexpr bool needs_neighborhoods = false;

  explicit Embedded(const EmbeddingOptions& options = {}) : options_(options) {}

  /// Embeds problem.hr.V (M×3) in problem.lr (tets over N vertices). Throws MeshError for an
  /// empty or degenerate LR mesh, ArgumentError for non-finite HR vertices.
  template <exec::HostPolicy Policy>
  void fit(Policy policy, UpsamplingProblem<S>& problem) {
    fit(policy, problem.lr, problem.hr.V);
  }

  /// Embeds the points `hr_rest` (M×3) in the tet mesh `lr_rest`.
  template <exec::HostPolicy Policy, class DQ>
  void fit(Policy policy, const TetMesh<S>& lr_rest, const Eigen::MatrixBase<DQ>& hr_rest) {
    embedding_ = embed(policy, lr_rest, hr_rest, options_);
    const Index m = embedding_.size();
    ids_.resize(m, 4);
    for (Index q = 0; q < m; ++q) ids_.row(q) = lr_rest.T.row(embedding_.tet[q]);
    num_lr_ = lr_rest.num_vertices();
  }

  /// hr_displacement.row(q) = Σ_k w_qk · lr_displacement.row(id_qk). Sizes N×3 and M×3 are
  /// checked (ShapeError); nothing is allocated.
  template <exec::HostPolicy P, class DI, class DO>
  void apply(P policy, const Eigen::MatrixBase<DI>& lr_displacement, Eigen::MatrixBase<DO>& hr_displacement) const {
    if (lr_displacement.rows() != num_lr_ || lr_displacement.cols() != 3)
      throw ShapeError("Embedded::apply: LR displacement", {num_lr_, 3}, {lr_displacement.rows(), lr_displacement.cols()});
    if (hr_displacement.rows() != num_hr() || hr_displacement.cols() != 3)
      throw ShapeError("Embedded::apply: HR displacement", {num_hr(), 3}, {hr_displacement.rows(), hr_displacement.cols()});
    using In = detail::EigenAccess<const DI>;
    using Out = detail::EigenAccess<DO>;
    exec::parallel_for(policy, num_hr(),
                       detail::EmbeddedApply<S, In, Out>{embedding_.weights.data(), ids_.data(), In{&lr_displacement.derived()}, Out{&hr_displacement.derived()}});
  }

  /// N, the LR vertex count fitted on (0 before fit).
  Index num_lr() const { return num_lr_; }
  /// M, the HR vertex count fitted on (0 before fit).
  Index num_hr() const { return embedding_.size(); }
  /// The embedding of the HR rest vertices (tet, weights, inside, distance per HR vertex).
  const Embedding<S>& embedding() const { return embedding_; }
  /// M×4 LR vertex ids of each HR vertex's tet (the columns of `embedding().weights`).
  const Tets& lr_vertex_ids() const { return ids_; }

 private:
  EmbeddingOptions options_;
  Embedding<S> embedding_;
  Tets ids_;
  Index num_lr_ = 0;
};

static_assert(assert_interpolator<Embedded<double>>());
static_assert(assert_interpolator<Embedded<float>>());

}  // namespace simsr::interp
