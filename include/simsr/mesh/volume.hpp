#pragma once
/// \file
/// Signed tet volumes and the total volume of a tet mesh.

#include <functional>

#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "detail/elements.hpp"

namespace simsr {

/// Signed volume of every tet, (v1−v0)·((v2−v0)×(v3−v0))/6: positive for TetMesh's orientation,
/// negative for inverted tets. V #V×3, T #T×4 (indices in range, see validate) → #T.
template <exec::HostPolicy P, class DV, class DT>
VecX<typename DV::Scalar> signed_volumes(P policy, const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DT>& T) {
  using S = typename DV::Scalar;
  detail::require_cols("signed_volumes: V", V, 3);
  detail::require_cols("signed_volumes: T", T, 4);
  VecX<S> vol(T.rows());
  exec::parallel_for(policy, T.rows(), [&](Index t) {
    vol[t] = detail::tet_volume6(detail::point(V, T(t, 0)), detail::point(V, T(t, 1)), detail::point(V, T(t, 2)),
                                 detail::point(V, T(t, 3))) / S(6);
  });
  return vol;
}

/// Sum of the signed tet volumes (V #V×3, T #T×4): the enclosed volume of a positively oriented
/// mesh. seq and omp round identically.
template <exec::HostPolicy P, class DV, class DT>
typename DV::Scalar total_volume(P policy, const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DT>& T) {
  using S = typename DV::Scalar;
  detail::require_cols("total_volume: V", V, 3);
  detail::require_cols("total_volume: T", T, 4);
  return exec::parallel_reduce(
             policy, T.rows(), S(0),
             [&](Index t) {
               return detail::tet_volume6(detail::point(V, T(t, 0)), detail::point(V, T(t, 1)),
                                          detail::point(V, T(t, 2)), detail::point(V, T(t, 3)));
             },
             std::plus<>{}) /
         S(6);
}

}  // namespace simsr
