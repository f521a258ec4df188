#pragma once
/// \file
/// Wavefront OBJ: polygon meshes, and the official super-resolution data's tet meshes written as
/// "tet soups" (4 triangles per tet).
///
///     auto poly = simsr::io::read_obj("face.obj");             // PolyMesh, faces of any size
///     auto tri  = simsr::io::read_obj_triangles("face.obj");   // TriMesh (simsr::triangulate)
///     auto tets = simsr::io::read_obj_tets("lrestshape.obj");  // TetMesh from 4 faces per tet
///
/// Reading: `v x y z [w] [r g b]` (the first three numbers are the position; every number must be
/// finite), `f` with corners `a`, `a/b`, `a/b/c`, `a//c` (1-based; negative = relative to the last
/// vertex defined so far; a face may only use vertices defined above it), `#` comments, CRLF.
/// `vt vn vp o g s usemtl mtllib` are ignored; any other statement (`l`, `p`, free-form curves...)
/// is a ParseError rather than a silent drop.
///
/// Tet-soup convention (the bunny's lrestshape.obj, 4,896 tets): faces 4k..4k+3 are the four
/// faces of tet k, each oriented outward (counter-clockwise seen from outside the tet). With the
/// first face (a,b,c) and d the vertex not on it, the positively oriented tet is **(a, c, b, d)**:
/// (c−a)·((b−a)×(d−a)) > 0; (a,b,c,d) itself is negative for every bunny tet. write_obj_tets
/// writes tet (t0,t1,t2,t3) as faces (t0,t2,t1) (t0,t1,t3) (t0,t3,t2) (t1,t2,t3), which
/// read_obj_tets maps back to (t0,t1,t2,t3) exactly; the bunny's files use this face order for
/// most tets and swap the 2nd and 3rd face for others, which reads identically.

#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../mesh/poly_mesh.hpp"
#include "../mesh/tet_mesh.hpp"
#include "../mesh/tri_mesh.hpp"
#include "../mesh/triangulate.hpp"
#include "detail/text_reader.hpp"

namespace simsr::io {

namespace detail {

/// Parses OBJ text; `face_lines`, if given, receives the 1-based line of every face.
template <class S>
PolyMesh<S> parse_obj(std::string_view text, std::string name, std::vector<std::int64_t>* face_lines) {
  LineCursor cur(text, std::move(name));
  std::vector<S> xyz;
  PolyMesh<S> mesh;
  std::vector<std::string_view> tok;
  if (face_lines) face_lines->clear();
  while (cur.next_content('#')) {
    split(cur.line(), tok);
    const std::string_view kw = tok[0];
    if (kw == "v") {
      if (tok.size() < 4 || tok.size() > 8)
        cur.fail("vertex needs 3 coordinates (optionally w and/or r g b), got " + std::to_string(tok.size() - 1) + " numbers");
      for (std::size_t k = 1; k < tok.size(); ++k) {
        const S x = cur.real<S>(tok[k], "vertex coordinate");
        if (k <= 3) xyz.push_back(x);
      }
      if (xyz.size() / 3 > static_cast<std::size_t>(std::numeric_limits<VIndex>::max())) cur.fail("too many vertices");
    } else if (kw == "f") {
      if (tok.size() < 4) cur.fail("face needs at least 3 corners, got " + std::to_string(tok.size() - 1));
      const auto nv = static_cast<std::int64_t>(xyz.size() / 3);
      for (std::size_t k = 1; k < tok.size(); ++k) {
        const std::string_view c = tok[k];
        // a, a/b, a/b/c, a//c: every present component an integer, at most three components.
        std::array<std::string_view, 3> part{};
        std::size_t parts = 0, start = 0;
        for (std::size_t i = 0; i <= c.size(); ++i) {
          if (i == c.size() || c[i] == '/') {
            if (parts == 3) cur.fail("face corner " + quote(c) + " has more than three components");
            part[parts++] = c.substr(start, i - start);
            start = i + 1;
          }
        }
        if (parts >= 2 && part[parts - 1].empty()) cur.fail("face corner " + quote(c) + " ends with '/'");
        for (std::size_t p = 1; p < parts; ++p) {
          if (part[p].empty()) continue;  // a//c
          if (cur.integer<std::int64_t>(part[p], "texture/normal index") == 0) cur.fail("index 0 in face corner " + quote(c) + " (OBJ indices start at 1)");
        }
        const auto v = cur.integer<std::int64_t>(part[0], "vertex index");
        std::int64_t i = 0;
        if (v > 0) {
          if (v > nv) cur.fail("vertex " + std::to_string(v) + " not defined above this face (" + std::to_string(nv) + " so far)");
          i = v - 1;
        } else if (v < 0) {
          if (-v > nv) cur.fail("relative vertex index " + std::to_string(v) + " reaches before the first vertex (" + std::to_string(nv) + " so far)");
          i = nv + v;
        } else {
          cur.fail("vertex index 0 (OBJ indices start at 1)");
        }
        mesh.indices.push_back(static_cast<VIndex>(i));
      }
      mesh.offsets.push_back(static_cast<Index>(mesh.indices.size()));
      if (face_lines) face_lines->push_back(cur.line_number());
    } else if (kw == "vt" || kw == "vn" || kw == "vp" || kw == "o" || kw == "g" || kw == "s" || kw == "usemtl" || kw == "mtllib") {
      continue;
    } else {
      cur.fail("unsupported OBJ statement " + quote(kw));
    }
  }
  mesh.V = Eigen::Map<const Points<S>>(xyz.data(), static_cast<Index>(xyz.size() / 3), 3);
  return mesh;
}

/// Checks the tet-soup convention; on failure returns false with the first bad group and why.
template <class S>
bool check_tet_soup(const PolyMesh<S>& poly, Index& bad_group, std::string& reason) {
  bad_group = -1;
  const Index nf = poly.num_faces();
  if (nf == 0) {
    reason = "no faces";
    return false;
  }
  for (Index f = 0; f < nf; ++f)
    if (poly.face_size(f) != 3) {
      bad_group = f / 4;
      reason = "face " + std::to_string(f) + " has " + std::to_string(poly.face_size(f)) + " corners, not 3";
      return false;
    }
  if (nf % 4 != 0) {
    bad_group = nf / 4;
    reason = std::to_string(nf) + " triangles is not a multiple of 4";
    return false;
  }
  for (Index g = 0; g < nf / 4; ++g) {
    const VIndex* c = poly.indices.data() + poly.offsets[4 * g];  // 12 corners (triangles are contiguous)
    std::array<VIndex, 4> verts{};
    int nverts = 0;
    bool ok = true;
    for (int k = 0; k < 12 && ok; ++k) {
      int j = 0;
      while (j < nverts && verts[j] != c[k]) ++j;
      if (j == nverts) {
        if (nverts == 4) ok = false;
        else verts[nverts++] = c[k];
      }
    }
    if (!ok || nverts != 4) {
      bad_group = g;
      reason = "faces " + std::to_string(4 * g) + ".." + std::to_string(4 * g + 3) + " do not use exactly 4 distinct vertices";
      return false;
    }
    // The 12 directed edges must be distinct: every face a triangle of the tet, no face twice,
    // all four consistently oriented (each edge once in each direction).
    std::array<std::pair<VIndex, VIndex>, 12> e{};
    for (int f = 0; f < 4; ++f)
      for (int k = 0; k < 3; ++k) e[3 * f + k] = {c[3 * f + k], c[3 * f + (k + 1) % 3]};
    for (int i = 0; i < 12 && ok; ++i) {
      if (e[i].first == e[i].second) ok = false;
      for (int j = i + 1; j < 12 && ok; ++j) ok = e[i] != e[j];
    }
    if (!ok) {
      bad_group = g;
      reason = "faces " + std::to_string(4 * g) + ".." + std::to_string(4 * g + 3) +
               " are not the four consistently oriented faces of one tet";
      return false;
    }
  }
  return true;
}

/// Tets of a checked tet soup, positively oriented per the convention above.
template <class S>
TetMesh<S> tets_from_soup(const PolyMesh<S>& poly) {
  TetMesh<S> m;
  m.V = poly.V;
  m.T.resize(poly.num_faces() / 4, 4);
  for (Index t = 0; t < m.T.rows(); ++t) {
    const VIndex* c = poly.indices.data() + poly.offsets[4 * t];
    VIndex d = c[3];
    for (int k = 3; k < 6; ++k)
      if (c[k] != c[0] && c[k] != c[1] && c[k] != c[2]) d = c[k];
    m.T.row(t) << c[0], c[2], c[1], d;
  }
  return m;
}

template <class S>
void append_obj_vertices(std::string& out, const Points<S>& V) {
  check_finite_points(V);
  for (Index i = 0; i < V.rows(); ++i) {
    out += "v ";
    append_real(out, V(i, 0));
    out += ' ';
    append_real(out, V(i, 1));
    out += ' ';
    append_real(out, V(i, 2));
    out += '\n';
  }
}

}  // namespace detail

/// Reads an OBJ polygon mesh held in memory; `name` labels error messages. V: #V×3, faces 0-based.
template <class S = Scalar>
PolyMesh<S> read_obj(std::string_view text, std::string name) {
  return detail::parse_obj<S>(text, std::move(name), nullptr);
}

/// Reads an OBJ polygon mesh from a file.
template <class S = Scalar>
PolyMesh<S> read_obj(const std::filesystem::path& path) {
  const std::string text = detail::read_text_file(path);
  return read_obj<S>(text, path.string());
}

/// Reads an OBJ file and triangulates its polygons (convex: fan from the first corner).
template <class S = Scalar>
TriMesh<S> read_obj_triangles(std::string_view text, std::string name) {
  return triangulate(read_obj<S>(text, std::move(name)));
}

/// Reads an OBJ file and triangulates its polygons.
template <class S = Scalar>
TriMesh<S> read_obj_triangles(const std::filesystem::path& path) {
  return triangulate(read_obj<S>(path));
}

/// True when `poly` is a tet soup: only triangles, a multiple of 4 of them, and every group of 4
/// consecutive faces the four consistently oriented faces of one tet (4 distinct vertices).
template <class S>
bool is_tet_soup(const PolyMesh<S>& poly) {
  Index g;
  std::string why;
  return detail::check_tet_soup(poly, g, why);
}

/// Reads a tet mesh written as 4 triangles per tet (see the file comment for the convention).
/// ParseError naming the line of the first face of the first bad group otherwise.
template <class S = Scalar>
TetMesh<S> read_obj_tets(std::string_view text, std::string name) {
  std::vector<std::int64_t> lines;
  const PolyMesh<S> poly = detail::parse_obj<S>(text, name, &lines);
  Index g;
  std::string why;
  if (!detail::check_tet_soup(poly, g, why)) {
    const std::int64_t line = g >= 0 && 4 * g < static_cast<Index>(lines.size()) ? lines[4 * g] : (lines.empty() ? 1 : lines.back());
    throw ParseError(name, line, "not a tet soup (4 triangles per tet): " + why);
  }
  return detail::tets_from_soup(poly);
}

/// Reads a tet-soup OBJ file.
template <class S = Scalar>
TetMesh<S> read_obj_tets(const std::filesystem::path& path) {
  const std::string text = detail::read_text_file(path);
  return read_obj_tets<S>(text, path.string());
}

/// OBJ text of a polygon mesh (shortest round-trip numbers, 1-based faces).
template <class S>
std::string format_obj(const PolyMesh<S>& mesh) {
  std::string out;
  detail::append_obj_vertices(out, mesh.V);
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    if (mesh.face_size(f) < 3) throw MeshError("polygon", f, "has fewer than 3 corners");
    out += 'f';
    for (Index k = mesh.offsets[f]; k < mesh.offsets[f + 1]; ++k) {
      const VIndex v = mesh.indices[k];
      if (v < 0 || v >= mesh.num_vertices()) throw MeshError("polygon", f, "vertex index " + std::to_string(v) + " out of range");
      out += ' ';
      detail::append_int(out, static_cast<std::int64_t>(v) + 1);
    }
    out += '\n';
  }
  return out;
}

/// OBJ text of a triangle mesh.
template <class S>
std::string format_obj(const TriMesh<S>& mesh) {
  detail::check_indices(mesh.F, mesh.num_vertices(), "triangle");
  std::string out;
  detail::append_obj_vertices(out, mesh.V);
  for (Index f = 0; f < mesh.F.rows(); ++f) {
    out += 'f';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      detail::append_int(out, static_cast<std::int64_t>(mesh.F(f, k)) + 1);
    }
    out += '\n';
  }
  return out;
}

/// OBJ text of a tet mesh in the 4-faces-per-tet convention. MeshError for an index out of range,
/// a tet with a repeated vertex (it would not read back) or a non-finite coordinate.
template <class S>
std::string format_obj_tets(const TetMesh<S>& mesh) {
  detail::check_indices(mesh.T, mesh.num_vertices(), "tet");
  std::string out;
  detail::append_obj_vertices(out, mesh.V);
  static constexpr int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (Index t = 0; t < mesh.T.rows(); ++t) {
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        if (mesh.T(t, a) == mesh.T(t, b)) throw MeshError("tet", t, "repeats vertex " + std::to_string(mesh.T(t, a)));
    for (const auto& f : faces) {
      out += 'f';
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        detail::append_int(out, static_cast<std::int64_t>(mesh.T(t, f[k])) + 1);
      }
      out += '\n';
    }
  }
  return out;
}

/// Writes a polygon mesh as OBJ.
template <class S>
void write_obj(const std::filesystem::path& path, const PolyMesh<S>& mesh) {
  detail::write_text_file(path, format_obj(mesh));
}

/// Writes a triangle mesh as OBJ.
template <class S>
void write_obj(const std::filesystem::path& path, const TriMesh<S>& mesh) {
  detail::write_text_file(path, format_obj(mesh));
}

/// Writes a tet mesh as OBJ, 4 outward triangles per tet (read back exactly by read_obj_tets).
template <class S>
void write_obj_tets(const std::filesystem::path& path, const TetMesh<S>& mesh) {
  detail::write_text_file(path, format_obj_tets(mesh));
}

}  // namespace simsr::io
