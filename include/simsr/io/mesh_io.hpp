#pragma once
/// \file
/// Any supported mesh file by its extension: the front door the `simsr` tool and scripts use.
///
///     auto m = simsr::io::read_mesh("cube.msh");        // tets and/or triangles, whatever it holds
///     simsr::io::write_mesh("cube.vtu", m);             // .obj .msh .node/.ele .mesh .vtu
///
/// | extension              | read | write | holds                                          |
/// |------------------------|------|-------|------------------------------------------------|
/// | .obj                   | yes  | yes   | polygons (triangulated) or a 4-triangles-per-tet soup |
/// | .msh (Gmsh 2.2, 4.1)   | yes  | yes   | tets + triangles                               |
/// | .node/.ele/.face       | yes  | yes   | tets (+ boundary faces)                        |
/// | .mesh (MEDIT)          | yes  | yes   | tets + triangles                               |
/// | .vtu (VTK XML)         | no   | yes   | tets + triangles (+ data, see vtu.hpp)         |
///
/// Nothing is silently dropped: writing tets and triangles to OBJ, which holds one or the other,
/// throws ArgumentError (keep one with `MeshData::keep`).

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "medit.hpp"
#include "msh.hpp"
#include "obj.hpp"
#include "tetgen.hpp"
#include "vtu.hpp"

namespace simsr::io {

/// File formats known by extension.
enum class MeshFormat { Obj, Msh, Tetgen, Medit, Vtu };

/// Vertices with tets and/or triangles, as a mesh file holds them.
template <class S = Scalar>
struct MeshData {
  Points<S> V;  ///< #V×3
  Tets T;       ///< #T×4 (may be empty)
  Tris F;       ///< #F×3 (may be empty; for OBJ the triangulated polygons)
  Index polygons = 0;          ///< OBJ: number of polygons before triangulation (0 otherwise)
  MeshFormat format = MeshFormat::Obj;
  std::string format_detail;   ///< e.g. "obj (tet soup)", "msh 4.1", "tetgen (1-based)"

  /// Drops the triangles ("tets") or the tets ("triangles"); ArgumentError otherwise.
  void keep(const std::string& what) {
    if (what == "tets")
      F.resize(0, 3);
    else if (what == "triangles")
      T.resize(0, 4);
    else
      throw ArgumentError("keep: expected 'tets' or 'triangles', got '" + what + "'");
  }
};

/// The format of `path` from its extension (case-insensitive); ArgumentError when unknown.
inline MeshFormat mesh_format(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".msh") return MeshFormat::Msh;
  if (ext == ".node" || ext == ".ele" || ext == ".face") return MeshFormat::Tetgen;
  if (ext == ".mesh") return MeshFormat::Medit;
  if (ext == ".vtu") return MeshFormat::Vtu;
  throw ArgumentError(path.string() + ": unknown mesh format '" + ext +
                      "' (known: .obj .msh .node/.ele/.face .mesh, and .vtu for writing)");
}

/// Reads a mesh file of any supported format. OBJ files in the 4-triangles-per-tet convention are
/// detected and read as tets; other OBJ polygons are triangulated.
template <class S = Scalar>
MeshData<S> read_mesh(const std::filesystem::path& path) {
  MeshData<S> m;
  m.format = mesh_format(path);
  switch (m.format) {
    case MeshFormat::Obj: {
      PolyMesh<S> poly = read_obj<S>(path);
      if (poly.num_faces() > 0 && is_tet_soup(poly)) {
        TetMesh<S> t = read_obj_tets<S>(path);
        m.V = std::move(t.V);
        m.T = std::move(t.T);
        m.format_detail = "obj (4 triangles per tet)";
      } else {
        m.polygons = poly.num_faces();
        TriMesh<S> t = triangulate(poly);
        m.V = std::move(t.V);
        m.F = std::move(t.F);
        m.format_detail = "obj";
      }
      break;
    }
    case MeshFormat::Msh: {
      MshMesh<S> g = read_msh<S>(path);
      m.V = std::move(g.V);
      m.T = std::move(g.T);
      m.F = std::move(g.F);
      m.format_detail = g.version == MshVersion::v22 ? "msh 2.2" : "msh 4.1";
      break;
    }
    case MeshFormat::Tetgen: {
      TetgenMesh<S> g = read_tetgen<S>(path);
      m.V = g.V;
      m.T = g.T;
      if (g.has_faces) m.F = tetgen_faces_outward(g);  // TetGen writes faces inward
      m.format_detail = g.first_index == 0 ? "tetgen (0-based)" : "tetgen (1-based)";
      break;
    }
    case MeshFormat::Medit: {
      MeditMesh<S> g = read_medit<S>(path);
      m.V = std::move(g.V);
      m.T = std::move(g.T);
      m.F = std::move(g.F);
      m.format_detail = "medit";
      break;
    }
    case MeshFormat::Vtu:
      throw ArgumentError(path.string() + ": .vtu is write-only in simsr (open it in ParaView or meshio)");
  }
  return m;
}

/// Options of write_mesh.
struct MeshWriteOptions {
  MshVersion msh_version = MshVersion::v41;
  VtuFormat vtu_format = VtuFormat::Binary;
};

/// Writes a mesh in the format of `path`'s extension. TetGen output names stem.node/.ele(/.face).
template <class S>
void write_mesh(const std::filesystem::path& path, const MeshData<S>& m, const MeshWriteOptions& opt = {}) {
  const bool tets = m.T.rows() > 0, tris = m.F.rows() > 0;
  switch (mesh_format(path)) {
    case MeshFormat::Obj:
      if (tets && tris)
        throw ArgumentError(path.string() + ": OBJ holds tets (4 triangles each) or triangles, not both: keep one (simsr convert --keep tets|triangles)");
      if (tets)
        write_obj_tets(path, TetMesh<S>{m.V, m.T});
      else
        write_obj(path, TriMesh<S>{m.V, m.F});
      break;
    case MeshFormat::Msh:
      write_msh(path, TetMesh<S>{m.V, m.T}, opt.msh_version, tris ? &m.F : nullptr);
      break;
    case MeshFormat::Tetgen: {
      if (!tets) throw ArgumentError(path.string() + ": TetGen files need tets; this mesh has only triangles");
      TetgenMesh<S> g;
      g.V = m.V;
      g.T = m.T;
      if (tris) {
        g.F = m.F;
        g.F.col(1).swap(g.F.col(2));  // TetGen's faces point inward
        g.has_faces = true;
      }
      write_tetgen(path, g);
      break;
    }
    case MeshFormat::Medit: {
      MeditMesh<S> g;
      g.V = m.V;
      g.T = m.T;
      g.F = m.F;
      write_medit(path, g);
      break;
    }
    case MeshFormat::Vtu: {
      VtuGrid grid;
      grid.set_points(m.V);
      if (tets) grid.set_tets(m.T);
      if (tris) grid.set_triangles(m.F);
      write_vtu(path, grid, opt.vtu_format);
      break;
    }
  }
}

}  // namespace simsr::io
