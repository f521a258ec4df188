#pragma once
/// \file
/// Polygon mesh (faces of any size, e.g. the quads of a scanned face), stored CSR-style.

#include <vector>

#include "../core/types.hpp"

namespace simsr {

/// Polygons with any number (≥ 3) of corners. Face f has corners
/// `indices[offsets[f] .. offsets[f+1])`; `offsets` has #faces+1 entries and starts at 0.
template <class S = Scalar>
struct PolyMesh {
  using scalar_type = S;
  Points<S> V;
  std::vector<VIndex> indices;
  std::vector<Index> offsets{0};

  Index num_vertices() const { return V.rows(); }
  Index num_faces() const { return static_cast<Index>(offsets.size()) - 1; }
  Index face_size(Index f) const { return offsets[f + 1] - offsets[f]; }
  /// Appends one polygon given by its corner indices.
  template <class Range>
  void add_face(const Range& corners) {
    for (auto c : corners) indices.push_back(static_cast<VIndex>(c));
    offsets.push_back(static_cast<Index>(indices.size()));
  }
};

}  // namespace simsr
