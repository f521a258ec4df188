#pragma once
/// \file
/// Triangle (surface) mesh: vertices #V×3 and triangles #F×3.

#include "../core/types.hpp"

namespace simsr {

/// A triangle mesh; faces are counter-clockwise seen from outside (normals point outward).
template <class S = Scalar>
struct TriMesh {
  using scalar_type = S;
  Points<S> V;  ///< #V×3 vertex positions
  Tris F;       ///< #F×3 vertex indices per triangle

  Index num_vertices() const { return V.rows(); }
  Index num_faces() const { return F.rows(); }
};

}  // namespace simsr
