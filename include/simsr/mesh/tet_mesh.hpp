#pragma once
/// \file
/// Tetrahedral mesh: vertices #V×3 and tets #T×4.

#include "../core/types.hpp"

namespace simsr {

/// A tetrahedral mesh. Tets are positively oriented when
/// (v1−v0)·((v2−v0)×(v3−v0)) > 0 (signed volume six times positive).
template <class S = Scalar>
struct TetMesh {
  using scalar_type = S;
  Points<S> V;  ///< #V×3 vertex positions
  Tets T;       ///< #T×4 vertex indices per tet

  Index num_vertices() const { return V.rows(); }
  Index num_tets() const { return T.rows(); }
};

}  // namespace simsr
