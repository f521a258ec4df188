#pragma once
/// \file
/// Gmsh .msh, ASCII versions 2.2 (also 2.0/2.1) and 4.1: linear tets (type 4) and triangles
/// (type 2) with their physical and elementary tags.
///
///     auto m = simsr::io::read_msh("cube.msh");        // MshMesh: V, T, F, tags, skipped types
///     simsr::TetMesh<> t = simsr::io::read_msh_tets("cube.msh");
///     simsr::io::write_msh("out.msh", t, simsr::io::MshVersion::v22);
///
/// Nodes keep file order; their tags (arbitrary, non-contiguous, up to 2^63−1) are mapped to rows
/// 0..#V−1 and kept in `node_tags`. Every other element type (points 15, lines 1, quads, quadratic
/// tets 11, ...) is skipped but counted per type in `skipped`. In 4.1, an element's physical tag
/// is the first physical tag of its entity in `$Entities` (0 when it has none), its elementary tag
/// the entity tag; in 2.x they are the element's first and second tags. `$PhysicalNames` is kept;
/// `$NodeData`, `$Periodic` and other sections are skipped. Binary files and version 4.0 are a
/// ParseError. Gmsh writes positively oriented tets ((v1−v0)·((v2−v0)×(v3−v0)) > 0): the order is
/// kept as in the file.

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../mesh/tet_mesh.hpp"
#include "detail/text_reader.hpp"

namespace simsr::io {

/// File format version of a .msh file.
enum class MshVersion { v22, v41 };

/// One `$PhysicalNames` entry.
struct MshPhysicalName {
  int dim = 0;
  int tag = 0;
  std::string name;
  bool operator==(const MshPhysicalName&) const = default;
};

/// Contents of a .msh file that simsr keeps.
template <class S = Scalar>
struct MshMesh {
  Points<S> V;                          ///< #V×3 node coordinates, file order
  std::vector<std::int64_t> node_tags;  ///< #V file tags of the nodes (row i has tag node_tags[i])
  Tets T;                               ///< #T×4 linear tets, rows of V
  Tris F;                               ///< #F×3 linear triangles, rows of V
  std::vector<int> tet_physical, tet_entity;  ///< #T physical (0: none) and elementary tags
  std::vector<int> tri_physical, tri_entity;  ///< #F physical (0: none) and elementary tags
  std::map<int, std::int64_t> skipped;        ///< element type → number of elements not kept
  std::vector<MshPhysicalName> physical_names;
  MshVersion version = MshVersion::v41;

  /// Total number of elements skipped.
  std::int64_t num_skipped() const {
    std::int64_t n = 0;
    for (const auto& [type, count] : skipped) n += count;
    return n;
  }
};

namespace detail {

/// Nodes per element and dimension of Gmsh element types (0 nodes: unknown type).
struct MshElementType {
  int nodes;
  int dim;
};
inline MshElementType msh_element_type(std::int64_t type) {
  switch (type) {
    case 1: return {2, 1};
    case 2: return {3, 2};
    case 3: return {4, 2};
    case 4: return {4, 3};
    case 5: return {8, 3};
    case 6: return {6, 3};
    case 7: return {5, 3};
    case 8: return {3, 1};
    case 9: return {6, 2};
    case 10: return {9, 2};
    case 11: return {10, 3};
    case 12: return {27, 3};
    case 13: return {18, 3};
    case 14: return {14, 3};
    case 15: return {1, 0};
    case 16: return {8, 2};
    case 17: return {20, 3};
    case 18: return {15, 3};
    case 19: return {13, 3};
    case 20: return {9, 2};
    case 21: return {10, 2};
    case 22: return {12, 2};
    case 23: return {15, 2};
    case 24: return {15, 2};
    case 25: return {21, 2};
    case 26: return {4, 1};
    case 27: return {5, 1};
    case 28: return {6, 1};
    case 29: return {20, 3};
    case 30: return {35, 3};
    case 31: return {56, 3};
    case 92: return {64, 3};
    case 93: return {125, 3};
    default: return {0, -1};
  }
}

/// Node tag → row lookup: dense when the tags span little more than their count, hashed otherwise.
class NodeTagMap {
 public:
  void build(const std::vector<std::int64_t>& tags, const LineCursor& cur, std::int64_t line) {
    dense_.clear();
    sparse_.clear();
    if (tags.empty()) return;
    const auto [lo, hi] = std::minmax_element(tags.begin(), tags.end());
    min_ = *lo;
    const auto span = static_cast<std::uint64_t>(*hi) - static_cast<std::uint64_t>(*lo);
    if (span < 4 * static_cast<std::uint64_t>(tags.size()) + 1024) {
      dense_.assign(span + 1, -1);
      for (std::size_t i = 0; i < tags.size(); ++i) {
        auto& slot = dense_[static_cast<std::size_t>(tags[i] - min_)];
        if (slot >= 0) cur.fail_at(line, "node tag " + std::to_string(tags[i]) + " defined twice");
        slot = static_cast<VIndex>(i);
      }
    } else {
      sparse_.reserve(tags.size());
      for (std::size_t i = 0; i < tags.size(); ++i)
        if (!sparse_.emplace(tags[i], static_cast<VIndex>(i)).second) cur.fail_at(line, "node tag " + std::to_string(tags[i]) + " defined twice");
    }
  }
  /// Row of node `tag`, or -1.
  VIndex find(std::int64_t tag) const {
    if (!dense_.empty()) {
      if (tag < min_ || static_cast<std::uint64_t>(tag) - static_cast<std::uint64_t>(min_) >= dense_.size()) return -1;
      return dense_[static_cast<std::size_t>(tag - min_)];
    }
    const auto it = sparse_.find(tag);
    return it == sparse_.end() ? -1 : it->second;
  }

 private:
  std::int64_t min_ = 0;
  std::vector<VIndex> dense_;
  std::unordered_map<std::int64_t, VIndex> sparse_;
};

template <class S>
class MshReader {
 public:
  MshReader(std::string_view text, std::string name) : cur_(text, std::move(name)) {}

  MshMesh<S> read() {
    while (cur_.next_content(0)) {
      const std::string_view head = cur_.line();
      if (head.empty() || head[0] != '$') cur_.fail("expected a section header such as $Nodes, got " + quote(head));
      const std::string section(head.substr(1));
      if (section == "MeshFormat") {
        read_format();
      } else if (!have_format_) {
        cur_.fail("file does not start with $MeshFormat (not a Gmsh .msh file?)");
      } else if (section == "PhysicalNames") {
        read_physical_names();
      } else if (section == "Entities" && v4_) {
        read_entities();
      } else if (section == "Nodes") {
        if (have_nodes_) cur_.fail("second $Nodes section");
        v4_ ? read_nodes_41() : read_nodes_22();
        have_nodes_ = true;
      } else if (section == "Elements") {
        if (!have_nodes_) cur_.fail("$Elements before $Nodes");
        if (have_elements_) cur_.fail("second $Elements section");
        v4_ ? read_elements_41() : read_elements_22();
        have_elements_ = true;
      } else if (section.rfind("End", 0) == 0) {
        cur_.fail("unexpected " + quote(head));
      } else {
        skip_section(section);
      }
    }
    if (!have_format_) cur_.fail_eof("$MeshFormat");
    if (!have_nodes_) cur_.fail_eof("a $Nodes section");
    m_.V = Eigen::Map<const Points<S>>(xyz_.data(), static_cast<Index>(xyz_.size() / 3), 3);
    m_.T = Eigen::Map<const Tets>(tets_.data(), static_cast<Index>(tets_.size() / 4), 4);
    m_.F = Eigen::Map<const Tris>(tris_.data(), static_cast<Index>(tris_.size() / 3), 3);
    return std::move(m_);
  }

 private:
  void split_line() { split(cur_.line(), tok_); }

  void expect_end(const std::string& section) {
    cur_.require_content("$End" + section, 0);
    if (cur_.line() != "$End" + section) cur_.fail("expected $End" + section + ", got " + quote(cur_.line()));
  }

  void skip_section(const std::string& section) {
    const std::int64_t start = cur_.line_number();
    while (cur_.next_content(0))
      if (cur_.line() == "$End" + section) return;
    cur_.fail_at(start, "section $" + section + " has no $End" + section);
  }

  void read_format() {
    if (have_format_) cur_.fail("second $MeshFormat section");
    cur_.require_content("version line 'version file-type data-size'", 0);
    split_line();
    if (tok_.size() != 3) cur_.fail("$MeshFormat line needs 'version file-type data-size', got " + quote(cur_.line()));
    const int file_type = cur_.integer<int>(tok_[1], "file type");
    if (file_type != 0) cur_.fail("binary .msh is not supported (file type " + std::to_string(file_type) + "); export ASCII (gmsh -format msh41 or msh22, without -bin)");
    const std::string_view v = tok_[0];
    if (v == "2" || v == "2.0" || v == "2.1" || v == "2.2") {
      v4_ = false;
      m_.version = MshVersion::v22;
    } else if (v == "4.1") {
      v4_ = true;
      m_.version = MshVersion::v41;
    } else {
      cur_.fail("unsupported .msh version " + quote(v) + " (supported: 2.2 and 4.1 ASCII)");
    }
    (void)cur_.integer<int>(tok_[2], "data size");
    have_format_ = true;
    expect_end("MeshFormat");
  }

  void read_physical_names() {
    cur_.require_content("number of physical names", 0);
    split_line();
    if (tok_.size() != 1) cur_.fail("expected the number of physical names");
    const auto n = cur_.count(tok_[0], 6, "physical names");
    for (std::int64_t i = 0; i < n; ++i) {
      cur_.require_content("physical name 'dim tag \"name\"'", 0);
      Tokens t(cur_.line());
      std::string_view a, b;
      if (!t.next(a) || !t.next(b)) cur_.fail("physical name needs 'dim tag \"name\"'");
      MshPhysicalName p;
      p.dim = cur_.integer<int>(a, "physical dimension");
      if (p.dim < 0 || p.dim > 3) cur_.fail("physical dimension " + std::to_string(p.dim) + " not in 0..3");
      p.tag = cur_.integer<int>(b, "physical tag");
      const std::string_view rest = trim(t.rest());
      if (rest.size() < 2 || rest.front() != '"' || rest.back() != '"') cur_.fail("physical name must be in double quotes, got " + quote(rest));
      p.name = std::string(rest.substr(1, rest.size() - 2));
      m_.physical_names.push_back(std::move(p));
    }
    expect_end("PhysicalNames");
  }

  void read_entities() {
    cur_.require_content("entity counts 'numPoints numCurves numSurfaces numVolumes'", 0);
    split_line();
    if (tok_.size() != 4) cur_.fail("$Entities needs 4 counts, got " + quote(cur_.line()));
    std::int64_t counts[4];
    std::int64_t total = 0;
    for (int d = 0; d < 4; ++d) {
      counts[d] = cur_.count(tok_[d], 10, "entities");
      total += counts[d];
    }
    cur_.check_count(total, 10, "entities");
    for (int d = 0; d < 4; ++d)
      for (std::int64_t i = 0; i < counts[d]; ++i) {
        cur_.require_content("an entity line", 0);
        split_line();
        // tag, box (3 numbers for points, 6 otherwise), physical tags, then bounding entities.
        const std::size_t box = d == 0 ? 3 : 6;
        if (tok_.size() < 2 + box) cur_.fail("entity line too short");
        const int tag = cur_.integer<int>(tok_[0], "entity tag");
        for (std::size_t k = 1; k <= box; ++k) (void)cur_.real<double>(tok_[k], "entity bounding box");
        std::size_t k = 1 + box;
        const auto nphys = cur_.integer<std::int64_t>(tok_[k++], "number of physical tags");
        if (nphys < 0 || static_cast<std::uint64_t>(nphys) > tok_.size() - k) cur_.fail("entity declares " + std::to_string(nphys) + " physical tags, line has fewer");
        int phys = 0;
        for (std::int64_t p = 0; p < nphys; ++p) {
          const int v = cur_.integer<int>(tok_[k++], "physical tag");
          if (p == 0) phys = v;
        }
        if (d > 0) {
          if (k >= tok_.size()) cur_.fail("entity line lacks its number of bounding entities");
          const auto nb = cur_.integer<std::int64_t>(tok_[k++], "number of bounding entities");
          if (nb < 0 || static_cast<std::uint64_t>(nb) != tok_.size() - k) cur_.fail("entity declares " + std::to_string(nb) + " bounding entities, line has " + std::to_string(tok_.size() - k));
          for (; k < tok_.size(); ++k) (void)cur_.integer<int>(tok_[k], "bounding entity tag");
        } else if (k != tok_.size()) {
          cur_.fail("point entity line has trailing tokens");
        }
        entity_physical_[{d, tag}] = phys;
      }
    expect_end("Entities");
  }

  void add_node(std::int64_t tag, const std::string_view* xyz) {
    for (int k = 0; k < 3; ++k) xyz_.push_back(cur_.real<S>(xyz[k], "node coordinate"));
    m_.node_tags.push_back(tag);
  }

  void read_nodes_22() {
    cur_.require_content("number of nodes", 0);
    split_line();
    if (tok_.size() != 1) cur_.fail("expected the number of nodes, got " + quote(cur_.line()));
    const auto n = cur_.count(tok_[0], 8, "nodes");
    xyz_.reserve(3 * static_cast<std::size_t>(n));
    m_.node_tags.reserve(static_cast<std::size_t>(n));
    for (std::int64_t i = 0; i < n; ++i) {
      cur_.require_content("node line 'tag x y z'", 0);
      split_line();
      if (tok_.size() != 4) cur_.fail("node line needs 'tag x y z', got " + std::to_string(tok_.size()) + " tokens");
      add_node(node_tag(tok_[0]), &tok_[1]);
    }
    const std::int64_t line = cur_.line_number();
    expect_end("Nodes");
    nodes_.build(m_.node_tags, cur_, line);
  }

  std::int64_t node_tag(std::string_view t) const {
    const auto tag = cur_.integer<std::int64_t>(t, "node tag");
    if (tag <= 0) cur_.fail("node tag " + std::to_string(tag) + " is not positive");
    return tag;
  }

  void read_nodes_41() {
    cur_.require_content("'numEntityBlocks numNodes minNodeTag maxNodeTag'", 0);
    split_line();
    if (tok_.size() != 4) cur_.fail("$Nodes header needs 'numEntityBlocks numNodes minNodeTag maxNodeTag'");
    const auto blocks = cur_.count(tok_[0], 8, "node blocks");
    const auto n = cur_.count(tok_[1], 8, "nodes");
    (void)cur_.integer<std::int64_t>(tok_[2], "minimum node tag");
    (void)cur_.integer<std::int64_t>(tok_[3], "maximum node tag");
    xyz_.reserve(3 * static_cast<std::size_t>(n));
    m_.node_tags.reserve(static_cast<std::size_t>(n));
    std::int64_t seen = 0;
    std::vector<std::int64_t> block_tags;
    for (std::int64_t b = 0; b < blocks; ++b) {
      cur_.require_content("node block header 'entityDim entityTag parametric numNodesInBlock'", 0);
      split_line();
      if (tok_.size() != 4) cur_.fail("node block header needs 'entityDim entityTag parametric numNodesInBlock'");
      const int dim = cur_.integer<int>(tok_[0], "entity dimension");
      if (dim < 0 || dim > 3) cur_.fail("entity dimension " + std::to_string(dim) + " not in 0..3");
      (void)cur_.integer<int>(tok_[1], "entity tag");
      const int parametric = cur_.integer<int>(tok_[2], "parametric flag");
      if (parametric != 0 && parametric != 1) cur_.fail("parametric flag must be 0 or 1");
      const auto k = cur_.integer<std::int64_t>(tok_[3], "count of nodes in block");
      if (k > n - seen) cur_.fail("node blocks hold more than the declared " + std::to_string(n) + " nodes");
      cur_.check_count(k, 8, "nodes in block");
      block_tags.clear();
      while (static_cast<std::int64_t>(block_tags.size()) < k) {
        cur_.require_content("node tags", 0);
        split_line();
        if (static_cast<std::int64_t>(tok_.size()) > k - static_cast<std::int64_t>(block_tags.size())) cur_.fail("more node tags than the block declares");
        for (auto t : tok_) block_tags.push_back(node_tag(t));
      }
      const std::size_t width = 3 + (parametric ? static_cast<std::size_t>(dim) : 0);
      for (std::int64_t i = 0; i < k; ++i) {
        cur_.require_content("node coordinates", 0);
        split_line();
        if (tok_.size() != width) cur_.fail("node coordinates need " + std::to_string(width) + " numbers, got " + std::to_string(tok_.size()));
        for (std::size_t p = 3; p < width; ++p) (void)cur_.real<double>(tok_[p], "parametric coordinate");
        add_node(block_tags[static_cast<std::size_t>(i)], tok_.data());
      }
      seen += k;
    }
    if (seen != n) cur_.fail("node blocks hold " + std::to_string(seen) + " nodes, header declares " + std::to_string(n));
    const std::int64_t line = cur_.line_number();
    expect_end("Nodes");
    nodes_.build(m_.node_tags, cur_, line);
  }

  VIndex node_row(std::string_view t) const {
    const auto tag = cur_.integer<std::int64_t>(t, "node tag");
    const VIndex r = nodes_.find(tag);
    if (r < 0) cur_.fail("element references undefined node tag " + std::to_string(tag));
    return r;
  }

  /// Keeps or counts one element whose node tags are `nodes` (already checked for count).
  void add_element(std::int64_t type, const std::string_view* nodes, std::size_t nn, int physical, int entity) {
    VIndex rows[4] = {0, 0, 0, 0};
    for (std::size_t k = 0; k < nn; ++k) {
      const VIndex r = node_row(nodes[k]);
      if (k < 4) rows[k] = r;
    }
    if (type == 4) {
      tets_.insert(tets_.end(), rows, rows + 4);
      m_.tet_physical.push_back(physical);
      m_.tet_entity.push_back(entity);
    } else if (type == 2) {
      tris_.insert(tris_.end(), rows, rows + 3);
      m_.tri_physical.push_back(physical);
      m_.tri_entity.push_back(entity);
    } else {
      ++m_.skipped[static_cast<int>(type)];
    }
  }

  int element_type(std::string_view t) const {
    const int type = cur_.integer<int>(t, "element type");
    if (type <= 0) cur_.fail("element type " + std::to_string(type) + " is not positive");
    return type;
  }

  void read_elements_22() {
    cur_.require_content("number of elements", 0);
    split_line();
    if (tok_.size() != 1) cur_.fail("expected the number of elements, got " + quote(cur_.line()));
    const auto n = cur_.count(tok_[0], 8, "elements");
    for (std::int64_t i = 0; i < n; ++i) {
      cur_.require_content("element line 'tag type ntags tags... nodes...'", 0);
      split_line();
      if (tok_.size() < 3) cur_.fail("element line needs 'tag type ntags tags... nodes...'");
      (void)cur_.integer<std::int64_t>(tok_[0], "element tag");
      const int type = element_type(tok_[1]);
      const auto ntags = cur_.integer<std::int64_t>(tok_[2], "number of tags");
      if (ntags < 0 || static_cast<std::uint64_t>(ntags) > tok_.size() - 3) cur_.fail("element declares " + std::to_string(ntags) + " tags, line has fewer tokens");
      int tags[2] = {0, 0};
      for (std::int64_t k = 0; k < ntags; ++k) {
        const int v = cur_.integer<int>(tok_[3 + static_cast<std::size_t>(k)], "element tag value");
        if (k < 2) tags[k] = v;
      }
      const std::size_t first = 3 + static_cast<std::size_t>(ntags), nn = tok_.size() - first;
      const auto info = msh_element_type(type);
      if (info.nodes == 0) {
        if (nn == 0) cur_.fail("element of unknown type " + std::to_string(type) + " has no nodes");
        ++m_.skipped[type];
        continue;
      }
      if (nn != static_cast<std::size_t>(info.nodes))
        cur_.fail("element of type " + std::to_string(type) + " needs " + std::to_string(info.nodes) + " nodes, got " + std::to_string(nn));
      add_element(type, &tok_[first], nn, tags[0], tags[1]);
    }
    expect_end("Elements");
  }

  void read_elements_41() {
    cur_.require_content("'numEntityBlocks numElements minElementTag maxElementTag'", 0);
    split_line();
    if (tok_.size() != 4) cur_.fail("$Elements header needs 'numEntityBlocks numElements minElementTag maxElementTag'");
    const auto blocks = cur_.count(tok_[0], 8, "element blocks");
    const auto n = cur_.count(tok_[1], 4, "elements");
    (void)cur_.integer<std::int64_t>(tok_[2], "minimum element tag");
    (void)cur_.integer<std::int64_t>(tok_[3], "maximum element tag");
    std::int64_t seen = 0;
    for (std::int64_t b = 0; b < blocks; ++b) {
      cur_.require_content("element block header 'entityDim entityTag elementType numElementsInBlock'", 0);
      split_line();
      if (tok_.size() != 4) cur_.fail("element block header needs 'entityDim entityTag elementType numElementsInBlock'");
      const int dim = cur_.integer<int>(tok_[0], "entity dimension");
      if (dim < 0 || dim > 3) cur_.fail("entity dimension " + std::to_string(dim) + " not in 0..3");
      const int entity = cur_.integer<int>(tok_[1], "entity tag");
      const int type = element_type(tok_[2]);
      const auto k = cur_.integer<std::int64_t>(tok_[3], "count of elements in block");
      if (k > n - seen) cur_.fail("element blocks hold more than the declared " + std::to_string(n) + " elements");
      cur_.check_count(k, 4, "elements in block");
      const auto info = msh_element_type(type);
      if (info.nodes != 0 && info.dim != dim)
        cur_.fail("element type " + std::to_string(type) + " has dimension " + std::to_string(info.dim) + ", block says " + std::to_string(dim));
      const auto it = entity_physical_.find({dim, entity});
      const int physical = it == entity_physical_.end() ? 0 : it->second;
      for (std::int64_t i = 0; i < k; ++i) {
        cur_.require_content("element line 'tag nodes...'", 0);
        split_line();
        (void)cur_.integer<std::int64_t>(tok_[0], "element tag");
        const std::size_t nn = tok_.size() - 1;
        if (info.nodes == 0) {
          if (nn == 0) cur_.fail("element of unknown type " + std::to_string(type) + " has no nodes");
          ++m_.skipped[type];
          continue;
        }
        if (nn != static_cast<std::size_t>(info.nodes))
          cur_.fail("element of type " + std::to_string(type) + " needs " + std::to_string(info.nodes) + " nodes, got " + std::to_string(nn));
        add_element(type, &tok_[1], nn, physical, entity);
      }
      seen += k;
    }
    if (seen != n) cur_.fail("element blocks hold " + std::to_string(seen) + " elements, header declares " + std::to_string(n));
    expect_end("Elements");
  }

  LineCursor cur_;
  MshMesh<S> m_;
  std::vector<std::string_view> tok_;
  std::vector<S> xyz_;
  std::vector<VIndex> tets_, tris_;
  NodeTagMap nodes_;
  std::map<std::pair<int, int>, int> entity_physical_;
  bool v4_ = false, have_format_ = false, have_nodes_ = false, have_elements_ = false;
};

/// Appends " x y z" (from coordinate `from` on) of vertex i.
template <class S>
void append_xyz(std::string& out, const Points<S>& V, Index i, int from = 0) {
  for (int k = from; k < 3; ++k) {
    out += ' ';
    append_real(out, V(i, k));
  }
}

}  // namespace detail

/// Reads a Gmsh .msh (2.2 or 4.1 ASCII) held in memory; `name` labels error messages.
template <class S = Scalar>
MshMesh<S> read_msh(std::string_view text, std::string name) {
  return detail::MshReader<S>(text, std::move(name)).read();
}

/// Reads a Gmsh .msh file (2.2 or 4.1 ASCII).
template <class S = Scalar>
MshMesh<S> read_msh(const std::filesystem::path& path) {
  const std::string text = detail::read_text_file(path);
  return read_msh<S>(text, path.string());
}

/// The tets of a .msh file held in memory (all nodes kept, in file order).
template <class S = Scalar>
TetMesh<S> read_msh_tets(std::string_view text, std::string name) {
  MshMesh<S> m = read_msh<S>(text, std::move(name));
  return TetMesh<S>{std::move(m.V), std::move(m.T)};
}

/// The tets of a .msh file (all nodes kept, in file order).
template <class S = Scalar>
TetMesh<S> read_msh_tets(const std::filesystem::path& path) {
  MshMesh<S> m = read_msh<S>(path);
  return TetMesh<S>{std::move(m.V), std::move(m.T)};
}

/// .msh text of `m` in the given version (ASCII). Node tags are m.node_tags (positive, distinct)
/// or 1..#V when empty; element tags 1..#F+#T (triangles first); empty tag vectors mean physical 0
/// and elementary 1. 4.1 stores physical tags per entity: MeshError if elements of one entity
/// disagree, ArgumentError for an entity tag ≤ 0. `skipped` is not written.
template <class S>
std::string format_msh(const MshMesh<S>& m, MshVersion version = MshVersion::v41) {
  const Index nv = m.V.rows(), nt = m.T.rows(), nf = m.F.rows();
  detail::check_finite_points(m.V);
  detail::check_indices(m.T, nv, "tet");
  detail::check_indices(m.F, nv, "triangle");
  auto check_size = [](const std::vector<int>& v, Index n, const char* what) {
    if (!v.empty() && static_cast<Index>(v.size()) != n) throw ShapeError(what, {n}, {static_cast<std::int64_t>(v.size())});
  };
  check_size(m.tet_physical, nt, "tet_physical");
  check_size(m.tet_entity, nt, "tet_entity");
  check_size(m.tri_physical, nf, "tri_physical");
  check_size(m.tri_entity, nf, "tri_entity");
  std::vector<std::int64_t> tags = m.node_tags;
  if (tags.empty()) {
    tags.resize(static_cast<std::size_t>(nv));
    for (Index i = 0; i < nv; ++i) tags[i] = i + 1;
  }
  if (static_cast<Index>(tags.size()) != nv) throw ShapeError("node_tags", {nv}, {static_cast<std::int64_t>(tags.size())});
  {
    std::vector<std::int64_t> sorted = tags;
    std::sort(sorted.begin(), sorted.end());
    if (!sorted.empty() && sorted.front() <= 0) throw ArgumentError("format_msh: node tags must be positive");
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) throw ArgumentError("format_msh: node tags must be distinct");
  }
  auto tag_of = [](const std::vector<int>& v, Index i, int fallback) { return v.empty() ? fallback : v[i]; };
  using detail::append_int;
  std::string out;
  out += version == MshVersion::v22 ? "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n" : "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  if (!m.physical_names.empty()) {
    out += "$PhysicalNames\n";
    append_int(out, m.physical_names.size());
    out += '\n';
    for (const auto& p : m.physical_names) {
      if (p.name.find('"') != std::string::npos || p.name.find('\n') != std::string::npos)
        throw ArgumentError("format_msh: physical name contains a quote or newline");
      append_int(out, p.dim);
      out += ' ';
      append_int(out, p.tag);
      out += " \"" + p.name + "\"\n";
    }
    out += "$EndPhysicalNames\n";
  }
  auto append_element_nodes = [&](auto row, int n) {
    for (int k = 0; k < n; ++k) {
      out += ' ';
      append_int(out, tags[static_cast<std::size_t>(row(k))]);
    }
    out += '\n';
  };
  if (version == MshVersion::v22) {
    out += "$Nodes\n";
    append_int(out, nv);
    out += '\n';
    for (Index i = 0; i < nv; ++i) {
      append_int(out, tags[i]);
      detail::append_xyz(out, m.V, i);
      out += '\n';
    }
    out += "$EndNodes\n$Elements\n";
    append_int(out, nf + nt);
    out += '\n';
    std::int64_t id = 1;
    for (Index f = 0; f < nf; ++f) {
      append_int(out, id++);
      out += " 2 2 ";
      append_int(out, tag_of(m.tri_physical, f, 0));
      out += ' ';
      append_int(out, tag_of(m.tri_entity, f, 1));
      append_element_nodes(m.F.row(f), 3);
    }
    for (Index t = 0; t < nt; ++t) {
      append_int(out, id++);
      out += " 4 2 ";
      append_int(out, tag_of(m.tet_physical, t, 0));
      out += ' ';
      append_int(out, tag_of(m.tet_entity, t, 1));
      append_element_nodes(m.T.row(t), 4);
    }
    out += "$EndElements\n";
    return out;
  }

  // 4.1: one entity per distinct elementary tag of each dimension, with its physical tag.
  struct Entity {
    int physical = 0;
    std::vector<Index> elements;
  };
  std::map<int, Entity> surfaces, volumes;
  auto collect = [](std::map<int, Entity>& into, const std::vector<int>& ent, const std::vector<int>& phys, Index n, const char* kind) {
    for (Index i = 0; i < n; ++i) {
      const int e = ent.empty() ? 1 : ent[i], p = phys.empty() ? 0 : phys[i];
      if (e <= 0) throw ArgumentError(std::string("format_msh: msh 4.1 needs positive entity tags, ") + kind + " " + std::to_string(i) + " has " + std::to_string(e));
      auto [it, fresh] = into.try_emplace(e);
      if (fresh) it->second.physical = p;
      else if (it->second.physical != p)
        throw MeshError(kind, i, "physical tag " + std::to_string(p) + " differs from " + std::to_string(it->second.physical) + " of other elements of entity " + std::to_string(e) + " (msh 4.1 stores one per entity)");
      it->second.elements.push_back(i);
    }
  };
  collect(surfaces, m.tri_entity, m.tri_physical, nf, "triangle");
  collect(volumes, m.tet_entity, m.tet_physical, nt, "tet");
  const bool extra_volume = volumes.empty() && surfaces.empty() && nv > 0;
  auto append_entity = [&](int tag, const Entity& e, auto rows, int corners) {
    Eigen::Matrix<S, 1, 3> lo = m.V.row(rows(e.elements.front(), 0)), hi = lo;
    for (Index i : e.elements)
      for (int k = 0; k < corners; ++k) {
        lo = lo.cwiseMin(m.V.row(rows(i, k)));
        hi = hi.cwiseMax(m.V.row(rows(i, k)));
      }
    append_int(out, tag);
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      detail::append_real(out, lo[k]);
    }
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      detail::append_real(out, hi[k]);
    }
    out += e.physical != 0 ? " 1 " + std::to_string(e.physical) + " 0\n" : " 0 0\n";
  };
  out += "$Entities\n0 0 ";
  append_int(out, surfaces.size());
  out += ' ';
  append_int(out, volumes.size() + (extra_volume ? 1 : 0));
  out += '\n';
  for (const auto& [tag, e] : surfaces) append_entity(tag, e, [&](Index i, int k) { return m.F(i, k); }, 3);
  for (const auto& [tag, e] : volumes) append_entity(tag, e, [&](Index i, int k) { return m.T(i, k); }, 4);
  if (extra_volume) out += "1 0 0 0 0 0 0 0 0\n";
  out += "$EndEntities\n";

  // All nodes in one block, classified on the first volume (or surface) entity.
  const int node_dim = volumes.empty() && !surfaces.empty() ? 2 : 3;
  const int node_entity = !volumes.empty() ? volumes.begin()->first : (!surfaces.empty() ? surfaces.begin()->first : 1);
  const auto [min_tag, max_tag] = tags.empty() ? std::pair<std::int64_t, std::int64_t>{0, 0}
                                               : std::pair<std::int64_t, std::int64_t>{*std::min_element(tags.begin(), tags.end()), *std::max_element(tags.begin(), tags.end())};
  out += "$Nodes\n";
  append_int(out, nv > 0 ? 1 : 0);
  out += ' ';
  append_int(out, nv);
  out += ' ';
  append_int(out, min_tag);
  out += ' ';
  append_int(out, max_tag);
  out += '\n';
  if (nv > 0) {
    out += std::to_string(node_dim) + ' ' + std::to_string(node_entity) + " 0 ";
    append_int(out, nv);
    out += '\n';
    for (Index i = 0; i < nv; ++i) {
      append_int(out, tags[i]);
      out += '\n';
    }
    for (Index i = 0; i < nv; ++i) {
      detail::append_real(out, m.V(i, 0));
      detail::append_xyz(out, m.V, i, 1);
      out += '\n';
    }
  }
  out += "$EndNodes\n$Elements\n";
  append_int(out, surfaces.size() + volumes.size());
  out += ' ';
  append_int(out, nf + nt);
  out += nf + nt > 0 ? " 1 " : " 0 ";
  append_int(out, nf + nt);
  out += '\n';
  std::int64_t id = 1;
  for (const auto& [tag, e] : surfaces) {
    out += "2 " + std::to_string(tag) + " 2 ";
    append_int(out, e.elements.size());
    out += '\n';
    for (Index f : e.elements) {
      append_int(out, id++);
      append_element_nodes(m.F.row(f), 3);
    }
  }
  for (const auto& [tag, e] : volumes) {
    out += "3 " + std::to_string(tag) + " 4 ";
    append_int(out, e.elements.size());
    out += '\n';
    for (Index t : e.elements) {
      append_int(out, id++);
      append_element_nodes(m.T.row(t), 4);
    }
  }
  out += "$EndElements\n";
  return out;
}

/// Writes `m` as a .msh file of the given version (ASCII); see format_msh.
template <class S>
void write_msh(const std::filesystem::path& path, const MshMesh<S>& m, MshVersion version = MshVersion::v41) {
  detail::write_text_file(path, format_msh(m, version));
}

/// Writes a tet mesh (and optionally its boundary triangles, #F×3 rows of mesh.V) as .msh;
/// node tags 1..#V, elementary tag 1, no physical tags.
template <class S>
void write_msh(const std::filesystem::path& path, const TetMesh<S>& mesh, MshVersion version = MshVersion::v41, const Tris* boundary = nullptr) {
  MshMesh<S> m;
  m.V = mesh.V;
  m.T = mesh.T;
  if (boundary) m.F = *boundary;
  m.version = version;
  write_msh(path, m, version);
}

}  // namespace simsr::io
