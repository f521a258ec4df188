#pragma once
/// \file
/// TetGen's .node / .ele / .face files (https://wias-berlin.de/software/tetgen/fformats.html).
///
///     auto m = simsr::io::read_tetgen("cube.1.ele");   // any of the three paths: siblings derived
///     simsr::io::write_tetgen("out.node", m);         // out.node, out.ele (+ out.face)
///
/// Numbering: the first node number of the .node file decides 0- or 1-based indexing for all three
/// files (as TetGen does); later node and element numbers must follow consecutively. `#` starts a
/// comment. Attributes and boundary markers are kept. A 10-node .ele (tetgen -o2) keeps the 4
/// corners in T and the 6 mid-edge nodes in `tet_edge_nodes`; 6-node faces likewise keep corners
/// in F. Extra .face columns of `tetgen -nn` (adjacent tets) are checked and dropped.
///
/// Orientation, measured with Debian's tetgen 1.6 (`tetgen -pq1.4a0.02 cube.poly`, 153 tets, and
/// `-pza0.2o2`, 22 tets; tests/data/io): every .ele tet is positively oriented in simsr's sense,
/// (v1−v0)·((v2−v0)×(v3−v0)) > 0, and every boundary .face triangle has its normal pointing
/// **into** the mesh (144/144 and 36/36), the opposite of simsr's outward TriMesh convention.
/// The reader keeps both as written; tetgen_faces_outward() returns the faces flipped explicitly.

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../mesh/tet_mesh.hpp"
#include "detail/text_reader.hpp"

namespace simsr::io {

/// Contents of a .node/.ele(/.face) triple.
template <class S = Scalar>
struct TetgenMesh {
  using Attributes = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Points<S> V;                     ///< #V×3 all nodes (mid-edge nodes of 10-node files included)
  Attributes node_attributes;      ///< #V×A point attributes (A may be 0)
  std::vector<int> node_markers;   ///< #V boundary markers, empty when the .node has none
  Tets T;                          ///< #T×4 tet corners as written (positively oriented by TetGen)
  Eigen::Matrix<VIndex, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> tet_edge_nodes;  ///< #T×6 for 10-node .ele, else #T×0
  Attributes tet_attributes;       ///< #T×A region attributes
  Tris F;                          ///< #F×3 .face corners as written (TetGen: normals point inward)
  std::vector<int> face_markers;   ///< #F boundary markers, empty when the .face has none
  bool has_faces = false;          ///< a .face file was read (or should be written)
  int first_index = 1;             ///< numbering base of the files: 0 or 1

  TetMesh<S> tet_mesh() const { return TetMesh<S>{V, T}; }
};

/// The three texts of a TetGen triple (face empty when there are no faces).
struct TetgenText {
  std::string node, ele, face;
};

namespace detail {

/// Reads the optional trailing numbers of a line: A attributes then M (0/1) marker.
template <class S, class Attributes>
void read_attributes(const LineCursor& cur, const std::vector<std::string_view>& tok, std::size_t first, Index row,
                     Attributes& attr, std::vector<int>* markers, bool has_marker) {
  for (Index a = 0; a < attr.cols(); ++a) attr(row, a) = cur.real<S>(tok[first + static_cast<std::size_t>(a)], "attribute");
  if (has_marker) markers->push_back(cur.integer<int>(tok[first + static_cast<std::size_t>(attr.cols())], "boundary marker"));
}

/// Header of a TetGen file: `count` then up to `max_fields - 1` optional integers (defaults given).
inline std::vector<std::int64_t> tetgen_header(LineCursor& cur, const std::vector<std::int64_t>& defaults, const char* what) {
  cur.require_content(std::string("the ") + what + " header line");
  std::vector<std::string_view> tok;
  split(cur.line(), tok);
  if (tok.size() > defaults.size()) cur.fail(std::string(what) + " header has " + std::to_string(tok.size()) + " numbers, at most " + std::to_string(defaults.size()) + " expected");
  std::vector<std::int64_t> v = defaults;
  for (std::size_t i = 0; i < tok.size(); ++i) v[i] = cur.integer<std::int64_t>(tok[i], std::string(what) + " header field");
  return v;
}

/// The element number of the line: must be base + i (consecutive numbering).
inline void check_number(const LineCursor& cur, std::string_view tok, std::int64_t expected, const char* what) {
  const auto n = cur.integer<std::int64_t>(tok, std::string(what) + " number");
  if (n != expected) cur.fail(std::string(what) + " number " + std::to_string(n) + " where " + std::to_string(expected) + " was expected (numbering must be consecutive)");
}

template <class S>
void parse_tetgen_node(std::string_view text, const std::string& name, TetgenMesh<S>& m) {
  LineCursor cur(text, name);
  const auto h = tetgen_header(cur, {0, 3, 0, 0}, ".node");
  if (h[1] != 3) cur.fail("dimension " + std::to_string(h[1]) + ": only 3-D .node files are supported");
  cur.check_count(h[2], 2, "point attributes");
  if (h[3] != 0 && h[3] != 1) cur.fail("boundary marker flag must be 0 or 1, got " + std::to_string(h[3]));
  const std::int64_t n = h[0], nattr = h[2];
  const bool markers = h[3] == 1;
  cur.check_count(n, 2 * static_cast<std::size_t>(4 + nattr + h[3]), "nodes");
  const std::size_t width = 4 + static_cast<std::size_t>(nattr) + (markers ? 1 : 0);
  m.V.resize(n, 3);
  m.node_attributes.resize(n, nattr);
  m.node_markers.clear();
  if (markers) m.node_markers.reserve(static_cast<std::size_t>(n));
  std::vector<std::string_view> tok;
  for (std::int64_t i = 0; i < n; ++i) {
    cur.require_content("node " + std::to_string(i + 1) + " of " + std::to_string(n));
    split(cur.line(), tok);
    if (tok.size() != width) cur.fail("node line needs " + std::to_string(width) + " numbers (index x y z, " + std::to_string(nattr) + " attributes, " + std::to_string(h[3]) + " marker), got " + std::to_string(tok.size()));
    if (i == 0) {
      const auto first = cur.integer<std::int64_t>(tok[0], "node number");
      if (first != 0 && first != 1) cur.fail("first node number must be 0 or 1 (it sets the numbering base), got " + std::to_string(first));
      m.first_index = static_cast<int>(first);
    } else {
      check_number(cur, tok[0], m.first_index + i, "node");
    }
    for (int k = 0; k < 3; ++k) m.V(i, k) = cur.real<S>(tok[1 + static_cast<std::size_t>(k)], "node coordinate");
    read_attributes<S>(cur, tok, 4, i, m.node_attributes, &m.node_markers, markers);
  }
  if (cur.next_content()) cur.fail("unexpected content after the " + std::to_string(n) + " declared nodes");
}

template <class S>
void parse_tetgen_ele(std::string_view text, const std::string& name, TetgenMesh<S>& m) {
  LineCursor cur(text, name);
  const auto h = tetgen_header(cur, {0, 4, 0}, ".ele");
  if (h[1] != 4 && h[1] != 10) cur.fail("nodes per tet must be 4 or 10, got " + std::to_string(h[1]));
  cur.check_count(h[2], 2, "region attributes");
  const std::int64_t n = h[0], npt = h[1], nattr = h[2];
  cur.check_count(n, 2 * static_cast<std::size_t>(1 + npt + nattr), "tets");
  const std::size_t width = 1 + static_cast<std::size_t>(npt + nattr);
  const std::int64_t nv = m.V.rows(), base = m.first_index;
  m.T.resize(n, 4);
  m.tet_edge_nodes.resize(n, npt - 4);
  m.tet_attributes.resize(n, nattr);
  std::vector<std::string_view> tok;
  for (std::int64_t i = 0; i < n; ++i) {
    cur.require_content("tet " + std::to_string(i + 1) + " of " + std::to_string(n));
    split(cur.line(), tok);
    if (tok.size() != width) cur.fail("tet line needs " + std::to_string(width) + " numbers, got " + std::to_string(tok.size()));
    check_number(cur, tok[0], base + i, "tet");
    for (std::int64_t k = 0; k < npt; ++k) {
      const VIndex v = cur.index(tok[1 + static_cast<std::size_t>(k)], base, nv, "tet node");
      if (k < 4) m.T(i, k) = v;
      else m.tet_edge_nodes(i, k - 4) = v;
    }
    read_attributes<S>(cur, tok, 1 + static_cast<std::size_t>(npt), i, m.tet_attributes, nullptr, false);
  }
  if (cur.next_content()) cur.fail("unexpected content after the " + std::to_string(n) + " declared tets");
}

template <class S>
void parse_tetgen_face(std::string_view text, const std::string& name, TetgenMesh<S>& m) {
  LineCursor cur(text, name);
  const auto h = tetgen_header(cur, {0, 0}, ".face");
  if (h[1] != 0 && h[1] != 1) cur.fail("boundary marker flag must be 0 or 1, got " + std::to_string(h[1]));
  const std::int64_t n = h[0], nv = m.V.rows(), base = m.first_index;
  const bool markers = h[1] == 1;
  cur.check_count(n, 8, "faces");
  m.F.resize(n, 3);
  m.face_markers.clear();
  m.has_faces = true;
  std::vector<std::string_view> tok;
  std::size_t nodes = 0;  // 3, or 6 for second-order faces; decided by the first line
  bool adjacent = false;  // tetgen -nn adds the two adjacent tets
  for (std::int64_t i = 0; i < n; ++i) {
    cur.require_content("face " + std::to_string(i + 1) + " of " + std::to_string(n));
    split(cur.line(), tok);
    const std::size_t rest = tok.size() - 1 - (markers ? 1 : 0);
    if (i == 0) {
      if (tok.size() < 1 + (markers ? 1u : 0u) || (rest != 3 && rest != 5 && rest != 6 && rest != 8))
        cur.fail("face line needs 'index a b c' (+3 mid-edge nodes) (+marker) (+2 adjacent tets), got " + std::to_string(tok.size()) + " numbers");
      nodes = rest == 3 || rest == 5 ? 3 : 6;
      adjacent = rest == 5 || rest == 8;
    } else if (tok.size() != 1 + nodes + (markers ? 1 : 0) + (adjacent ? 2 : 0)) {
      cur.fail("face line has " + std::to_string(tok.size()) + " numbers, earlier lines had " + std::to_string(1 + nodes + (markers ? 1 : 0) + (adjacent ? 2 : 0)));
    }
    check_number(cur, tok[0], base + i, "face");
    for (std::size_t k = 0; k < nodes; ++k) {
      const VIndex v = cur.index(tok[1 + k], base, nv, "face node");
      if (k < 3) m.F(i, static_cast<Index>(k)) = v;
    }
    std::size_t k = 1 + nodes;
    if (markers) m.face_markers.push_back(cur.integer<int>(tok[k++], "boundary marker"));
    if (adjacent)
      for (int a = 0; a < 2; ++a) {
        const auto t = cur.integer<std::int64_t>(tok[k++], "adjacent tet");
        if (t != -1 && (t < base || t - base >= m.T.rows())) cur.fail("adjacent tet " + std::to_string(t) + " out of range");
      }
  }
  if (cur.next_content()) cur.fail("unexpected content after the " + std::to_string(n) + " declared faces");
}

/// `p` without a .node/.ele/.face extension (other paths are taken as the stem itself).
inline std::filesystem::path tetgen_stem(const std::filesystem::path& p) {
  const auto ext = p.extension();
  if (ext == ".node" || ext == ".ele" || ext == ".face") return p.parent_path() / p.stem();
  return p;
}

inline std::filesystem::path with_suffix(const std::filesystem::path& stem, const char* suffix) {
  std::filesystem::path p = stem;
  p += suffix;
  return p;
}

}  // namespace detail

/// Reads a TetGen triple held in memory: texts of the .node, .ele and (optional) .face files;
/// errors name `name` + ".node" etc.
template <class S = Scalar>
TetgenMesh<S> read_tetgen(std::string_view node, std::string_view ele, std::optional<std::string_view> face, std::string name) {
  TetgenMesh<S> m;
  detail::parse_tetgen_node(node, name + ".node", m);
  detail::parse_tetgen_ele(ele, name + ".ele", m);
  if (face) detail::parse_tetgen_face(*face, name + ".face", m);
  return m;
}

/// Reads stem.node and stem.ele (required) and stem.face (when it exists), given any of the three
/// paths or the stem itself.
template <class S = Scalar>
TetgenMesh<S> read_tetgen(const std::filesystem::path& path) {
  const auto stem = detail::tetgen_stem(path);
  const auto face_path = detail::with_suffix(stem, ".face");
  const std::string node = detail::read_text_file(detail::with_suffix(stem, ".node"));
  const std::string ele = detail::read_text_file(detail::with_suffix(stem, ".ele"));
  std::optional<std::string> face;
  if (std::filesystem::exists(face_path)) face = detail::read_text_file(face_path);
  return read_tetgen<S>(node, ele, face ? std::optional<std::string_view>(*face) : std::nullopt, stem.string());
}

/// The tets of a TetGen triple (all nodes kept).
template <class S = Scalar>
TetMesh<S> read_tetgen_tets(const std::filesystem::path& path) {
  return read_tetgen<S>(path).tet_mesh();
}

/// The .face triangles flipped to simsr's outward convention (TetGen writes them inward).
template <class S>
Tris tetgen_faces_outward(const TetgenMesh<S>& m) {
  Tris F = m.F;
  F.col(1).swap(F.col(2));
  return F;
}

/// Texts of the TetGen triple of `m`, numbered from m.first_index; .face only when m.has_faces
/// or F is non-empty. Orders are written as given (no reorientation).
template <class S>
TetgenText format_tetgen(const TetgenMesh<S>& m) {
  using detail::append_int;
  using detail::append_real;
  const Index nv = m.V.rows(), nt = m.T.rows(), nf = m.F.rows();
  if (m.first_index != 0 && m.first_index != 1) throw ArgumentError("format_tetgen: first_index must be 0 or 1");
  detail::check_finite_points(m.V);
  detail::check_indices(m.T, nv, "tet");
  detail::check_indices(m.F, nv, "triangle");
  detail::check_indices(m.tet_edge_nodes, nv, "tet");
  if (m.node_attributes.rows() != nv && m.node_attributes.size() != 0) throw ShapeError("node_attributes", {nv, -1}, {m.node_attributes.rows(), m.node_attributes.cols()});
  if (m.tet_attributes.rows() != nt && m.tet_attributes.size() != 0) throw ShapeError("tet_attributes", {nt, -1}, {m.tet_attributes.rows(), m.tet_attributes.cols()});
  if (m.tet_edge_nodes.size() != 0 && (m.tet_edge_nodes.rows() != nt || m.tet_edge_nodes.cols() != 6)) throw ShapeError("tet_edge_nodes", {nt, 6}, {m.tet_edge_nodes.rows(), m.tet_edge_nodes.cols()});
  if (!m.node_markers.empty() && static_cast<Index>(m.node_markers.size()) != nv) throw ShapeError("node_markers", {nv}, {static_cast<std::int64_t>(m.node_markers.size())});
  if (!m.face_markers.empty() && static_cast<Index>(m.face_markers.size()) != nf) throw ShapeError("face_markers", {nf}, {static_cast<std::int64_t>(m.face_markers.size())});
  for (Index i = 0; i < m.node_attributes.size(); ++i)
    if (!std::isfinite(m.node_attributes.data()[i])) throw MeshError("vertex", i / std::max<Index>(m.node_attributes.cols(), 1), "non-finite attribute");
  for (Index i = 0; i < m.tet_attributes.size(); ++i)
    if (!std::isfinite(m.tet_attributes.data()[i])) throw MeshError("tet", i / std::max<Index>(m.tet_attributes.cols(), 1), "non-finite attribute");
  const Index na = m.node_attributes.rows() == nv && nv > 0 ? m.node_attributes.cols() : 0;
  const Index ta = m.tet_attributes.rows() == nt && nt > 0 ? m.tet_attributes.cols() : 0;
  const bool quadratic = m.tet_edge_nodes.size() != 0 && nt > 0;
  const int b = m.first_index;
  TetgenText out;
  std::string& s = out.node;
  s = "# written by simsr\n";
  append_int(s, nv);
  s += " 3 ";
  append_int(s, na);
  s += m.node_markers.empty() ? " 0\n" : " 1\n";
  for (Index i = 0; i < nv; ++i) {
    append_int(s, i + b);
    for (int k = 0; k < 3; ++k) {
      s += ' ';
      append_real(s, m.V(i, k));
    }
    for (Index a = 0; a < na; ++a) {
      s += ' ';
      append_real(s, m.node_attributes(i, a));
    }
    if (!m.node_markers.empty()) {
      s += ' ';
      append_int(s, m.node_markers[i]);
    }
    s += '\n';
  }
  std::string& e = out.ele;
  e = "# written by simsr\n";
  append_int(e, nt);
  e += quadratic ? " 10 " : " 4 ";
  append_int(e, ta);
  e += '\n';
  for (Index t = 0; t < nt; ++t) {
    append_int(e, t + b);
    for (int k = 0; k < 4; ++k) {
      e += ' ';
      append_int(e, static_cast<std::int64_t>(m.T(t, k)) + b);
    }
    if (quadratic)
      for (int k = 0; k < 6; ++k) {
        e += ' ';
        append_int(e, static_cast<std::int64_t>(m.tet_edge_nodes(t, k)) + b);
      }
    for (Index a = 0; a < ta; ++a) {
      e += ' ';
      append_real(e, m.tet_attributes(t, a));
    }
    e += '\n';
  }
  if (m.has_faces || nf > 0) {
    std::string& f = out.face;
    f = "# written by simsr\n";
    append_int(f, nf);
    f += m.face_markers.empty() ? " 0\n" : " 1\n";
    for (Index i = 0; i < nf; ++i) {
      append_int(f, i + b);
      for (int k = 0; k < 3; ++k) {
        f += ' ';
        append_int(f, static_cast<std::int64_t>(m.F(i, k)) + b);
      }
      if (!m.face_markers.empty()) {
        f += ' ';
        append_int(f, m.face_markers[i]);
      }
      f += '\n';
    }
  }
  return out;
}

/// Writes stem.node, stem.ele and (when there are faces) stem.face; `path` may be any of them or
/// the stem.
template <class S>
void write_tetgen(const std::filesystem::path& path, const TetgenMesh<S>& m) {
  const auto stem = detail::tetgen_stem(path);
  const TetgenText t = format_tetgen(m);
  detail::write_text_file(detail::with_suffix(stem, ".node"), t.node);
  detail::write_text_file(detail::with_suffix(stem, ".ele"), t.ele);
  if (m.has_faces || m.F.rows() > 0) detail::write_text_file(detail::with_suffix(stem, ".face"), t.face);
}

/// Writes a tet mesh as stem.node and stem.ele, 1-based like TetGen.
template <class S>
void write_tetgen(const std::filesystem::path& path, const TetMesh<S>& mesh) {
  TetgenMesh<S> m;
  m.V = mesh.V;
  m.T = mesh.T;
  write_tetgen(path, m);
}

}  // namespace simsr::io
