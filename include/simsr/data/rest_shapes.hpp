#pragma once
/// \file
/// The two rest shapes of a super-resolution pair, read from mesh files:
///
///     TetMesh<> lr = data::read_lr_rest("lrestshape.obj");   // LR volume (any tet format)
///     TriMesh<> hr = data::read_hr_rest("hrestshape.obj");   // HR surface, vertices in the frames' order

#include <filesystem>
#include <string>
#include <utility>

#include "../core/error.hpp"
#include "../io/mesh_io.hpp"
#include "../mesh/tet_mesh.hpp"
#include "../mesh/tri_mesh.hpp"

namespace simsr::data {

/// The LR rest volume mesh: .msh, TetGen .node/.ele, MEDIT .mesh, or the authors' OBJ with four
/// triangles per tet. ArgumentError when the file holds no tets.
inline TetMesh<Scalar> read_lr_rest(const std::filesystem::path& file) {
  auto m = io::read_mesh(file);
  if (m.T.rows() == 0) throw ArgumentError(file.string() + ": the LR rest shape must be a tet mesh (it has no tets)");
  return {std::move(m.V), std::move(m.T)};
}

/// The HR rest surface (any triangle format). A tet mesh is refused rather than replaced by its
/// boundary: the HR vertex order must be the frames' order. ArgumentError without triangles.
inline TriMesh<Scalar> read_hr_rest(const std::filesystem::path& file) {
  auto m = io::read_mesh(file);
  if (m.F.rows() == 0) throw ArgumentError(file.string() + ": the HR rest shape must be a triangle surface (it has no triangles)");
  return {std::move(m.V), std::move(m.F)};
}

}  // namespace simsr::data
