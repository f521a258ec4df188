#pragma once
/// \file
/// MEDIT / INRIA .mesh, ASCII (as written by meshio, gmsh -format mesh, mmg, TetGen -g).
///
///     auto m = simsr::io::read_medit("cube.mesh");   // MeditMesh: V, F, T and their refs
///     simsr::io::write_medit("out.mesh", m);
///
/// Free format: keywords and numbers separated by any whitespace, `#` comments. Keywords are
/// case-sensitive as written by meshio and gmsh: MeshVersionFormatted (1..4), Dimension (3 only;
/// value on the same or the next line), Vertices (x y z ref), Triangles (a b c ref), Tetrahedra
/// (a b c d ref), End (required: a file without it is reported as truncated). Indices are 1-based.
/// Other known sections (Edges, Quadrilaterals, Hexahedra, Prisms, Pyramids, P2/Q2 elements,
/// Corners, Ridges, Required*, Normals, Tangents, ...) are skipped and counted in `skipped`; an
/// unknown keyword is a ParseError. Orientation is kept as written (gmsh and meshio write
/// positively oriented tets, (v1−v0)·((v2−v0)×(v3−v0)) > 0, see tests/data/io/expected.json).

#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../mesh/tet_mesh.hpp"
#include "detail/text_reader.hpp"

namespace simsr::io {

/// Contents of a MEDIT .mesh file that simsr keeps.
template <class S = Scalar>
struct MeditMesh {
  Points<S> V;                   ///< #V×3 vertices
  std::vector<int> vertex_refs;  ///< #V references (labels)
  Tris F;                        ///< #F×3 triangles, 0-based
  std::vector<int> tri_refs;     ///< #F references
  Tets T;                        ///< #T×4 tets, 0-based
  std::vector<int> tet_refs;     ///< #T references
  std::map<std::string, std::int64_t> skipped;  ///< skipped keyword → number of its entries
  int version = 2;               ///< MeshVersionFormatted (1: single, 2: double precision)

  TetMesh<S> tet_mesh() const { return TetMesh<S>{V, T}; }
};

namespace detail {

/// Tokens per entry of the MEDIT sections simsr skips (integers or reals), 0 if unknown.
inline int medit_skipped_width(std::string_view kw) {
  static const std::map<std::string_view, int> widths = {
      {"Edges", 3}, {"Quadrilaterals", 5}, {"Hexahedra", 9}, {"Prisms", 7}, {"Pyramids", 6},
      {"EdgesP2", 4}, {"TrianglesP2", 7}, {"QuadrilateralsQ2", 10}, {"TetrahedraP2", 11}, {"HexahedraQ2", 28},
      {"Corners", 1}, {"Ridges", 1}, {"RequiredVertices", 1}, {"RequiredEdges", 1}, {"RequiredTriangles", 1},
      {"RequiredQuadrilaterals", 1}, {"RequiredTetrahedra", 1}, {"Normals", 3}, {"Tangents", 3},
      {"NormalAtVertices", 2}, {"TangentAtVertices", 2}, {"NormalAtTriangleVertices", 3}, {"TangentAtEdgeVertices", 3}};
  const auto it = widths.find(kw);
  return it == widths.end() ? 0 : it->second;
}

template <class S>
MeditMesh<S> parse_medit(std::string_view text, std::string name) {
  LineCursor cur(text, std::move(name));
  TokenStream ts(cur, '#');
  MeditMesh<S> m;
  bool have_version = false, have_dim = false, have_vertices = false, have_tris = false, have_tets = false;
  std::string_view kw;
  auto count = [&](const std::string& what, int width) {
    const std::string_view tok = ts.expect("the number of " + what);
    return cur.count(tok, 2 * static_cast<std::size_t>(width), what, ts.bytes_left());
  };
  auto ref = [&](std::string_view tok) { return cur.integer<int>(tok, "reference"); };
  while (true) {
    if (!ts.next(kw)) cur.fail_eof("the keyword End (file truncated?)");
    if (kw == "End") break;
    if (!have_version && kw != "MeshVersionFormatted") cur.fail("expected MeshVersionFormatted first, got " + quote(kw) + " (not an ASCII MEDIT file?)");
    if (kw == "MeshVersionFormatted") {
      if (have_version) cur.fail("second MeshVersionFormatted");
      m.version = cur.integer<int>(ts.expect("the format version"), "format version");
      if (m.version < 1 || m.version > 4) cur.fail("MeshVersionFormatted " + std::to_string(m.version) + " not in 1..4");
      have_version = true;
    } else if (kw == "Dimension") {
      const int d = cur.integer<int>(ts.expect("the dimension"), "dimension");
      if (d != 3) cur.fail("Dimension " + std::to_string(d) + ": only 3-D meshes are supported");
      have_dim = true;
    } else if (kw == "Vertices") {
      if (!have_dim) cur.fail("Vertices before Dimension");
      if (have_vertices) cur.fail("second Vertices section");
      const auto n = count("vertices", 4);
      m.V.resize(n, 3);
      m.vertex_refs.resize(static_cast<std::size_t>(n));
      for (std::int64_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) m.V(i, k) = cur.real<S>(ts.expect("vertex coordinates"), "vertex coordinate");
        m.vertex_refs[static_cast<std::size_t>(i)] = ref(ts.expect("a vertex reference"));
      }
      have_vertices = true;
    } else if (kw == "Triangles" || kw == "Tetrahedra") {
      const bool tet = kw == "Tetrahedra";
      if (!have_vertices) cur.fail(std::string(kw) + " before Vertices");
      if (tet ? have_tets : have_tris) cur.fail("second " + std::string(kw) + " section");
      const int corners = tet ? 4 : 3;
      const auto n = count(tet ? "tetrahedra" : "triangles", corners + 1);
      Eigen::Matrix<VIndex, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> E(n, corners);
      std::vector<int> refs(static_cast<std::size_t>(n));
      for (std::int64_t i = 0; i < n; ++i) {
        for (int k = 0; k < corners; ++k) E(i, k) = cur.index(ts.expect("element vertices"), 1, m.V.rows(), "vertex index");
        refs[static_cast<std::size_t>(i)] = ref(ts.expect("an element reference"));
      }
      if (tet) {
        m.T = E;
        m.tet_refs = std::move(refs);
        have_tets = true;
      } else {
        m.F = E;
        m.tri_refs = std::move(refs);
        have_tris = true;
      }
    } else if (const int width = medit_skipped_width(kw); width > 0) {
      const std::string key(kw);
      const auto n = count(key, width);
      for (std::int64_t i = 0; i < n * width; ++i) (void)cur.real<double>(ts.expect("an entry of " + key), key + " entry");
      m.skipped[key] += n;
    } else {
      cur.fail("unknown or unsupported MEDIT keyword " + quote(kw));
    }
  }
  if (!have_dim) cur.fail("End before Dimension");
  return m;
}

}  // namespace detail

/// Reads a MEDIT .mesh held in memory; `name` labels error messages.
template <class S = Scalar>
MeditMesh<S> read_medit(std::string_view text, std::string name) {
  return detail::parse_medit<S>(text, std::move(name));
}

/// Reads a MEDIT .mesh file (ASCII; .meshb binary is not supported).
template <class S = Scalar>
MeditMesh<S> read_medit(const std::filesystem::path& path) {
  const std::string text = detail::read_text_file(path);
  return read_medit<S>(text, path.string());
}

/// The tets of a MEDIT .mesh file (all vertices kept).
template <class S = Scalar>
TetMesh<S> read_medit_tets(const std::filesystem::path& path) {
  return read_medit<S>(path).tet_mesh();
}

/// MEDIT text of `m` (MeshVersionFormatted 2, shortest round-trip numbers; empty ref vectors
/// mean ref 0; sections without entries omitted).
template <class S>
std::string format_medit(const MeditMesh<S>& m) {
  using detail::append_int;
  const Index nv = m.V.rows();
  detail::check_finite_points(m.V);
  detail::check_indices(m.F, nv, "triangle");
  detail::check_indices(m.T, nv, "tet");
  auto check_refs = [](const std::vector<int>& r, Index n, const char* what) {
    if (!r.empty() && static_cast<Index>(r.size()) != n) throw ShapeError(what, {n}, {static_cast<std::int64_t>(r.size())});
  };
  check_refs(m.vertex_refs, nv, "vertex_refs");
  check_refs(m.tri_refs, m.F.rows(), "tri_refs");
  check_refs(m.tet_refs, m.T.rows(), "tet_refs");
  std::string out = "MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n";
  append_int(out, nv);
  out += '\n';
  for (Index i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) {
      detail::append_real(out, m.V(i, k));
      out += ' ';
    }
    append_int(out, m.vertex_refs.empty() ? 0 : m.vertex_refs[i]);
    out += '\n';
  }
  auto section = [&](const char* kw, const auto& E, const std::vector<int>& refs) {
    if (E.rows() == 0) return;
    out += "\n";
    out += kw;
    out += '\n';
    append_int(out, E.rows());
    out += '\n';
    for (Index i = 0; i < E.rows(); ++i) {
      for (Index k = 0; k < E.cols(); ++k) {
        append_int(out, static_cast<std::int64_t>(E(i, k)) + 1);
        out += ' ';
      }
      append_int(out, refs.empty() ? 0 : refs[i]);
      out += '\n';
    }
  };
  section("Triangles", m.F, m.tri_refs);
  section("Tetrahedra", m.T, m.tet_refs);
  out += "\nEnd\n";
  return out;
}

/// Writes `m` as an ASCII MEDIT .mesh file.
template <class S>
void write_medit(const std::filesystem::path& path, const MeditMesh<S>& m) {
  detail::write_text_file(path, format_medit(m));
}

/// Writes a tet mesh (refs 0) and optional boundary triangles as an ASCII MEDIT .mesh file.
template <class S>
void write_medit(const std::filesystem::path& path, const TetMesh<S>& mesh, const Tris* boundary = nullptr) {
  MeditMesh<S> m;
  m.V = mesh.V;
  m.T = mesh.T;
  if (boundary) m.F = *boundary;
  write_medit(path, m);
}

}  // namespace simsr::io
