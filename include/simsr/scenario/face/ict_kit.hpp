#pragma once
/// \file
/// The ICT FaceKit as bundled in `../shared/data/ict_face/` (MIT; units cm): the full neutral mesh
/// (`full_neutral.obj`: skin, mouth socket, eye sockets, gums and tongue, teeth, eyeballs), each
/// part's vertex range (`regions.json`) and every expression's displacement of all vertices
/// (`expressions_full.npz`: `names`, `deltas` E×V×3).
///
///     auto kit = simsr::scenario::read_ict_kit(data_dir / "ict_face");
///     PolyMesh<> skin = kit.faces_within({"face", "head_and_neck"});   // the open head surface
///     Points<> smile = kit.expression("mouthSmile_L");                  // V×3 displacements
///
/// Everything the face scenario takes from data starts here; every file is checked against the
/// others (ranges tile the vertices, every face lies in one region, the deltas match the mesh).

#include <algorithm>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/types.hpp"
#include "../../io/npz.hpp"
#include "../../io/obj.hpp"
#include "../../io/text_file.hpp"
#include "../../mesh/poly_mesh.hpp"

namespace simsr::scenario {

/// Vertices [first, last] (inclusive, as regions.json writes them) of one part of the kit.
struct VertexRange {
  Index first = 0;
  Index last = -1;
  Index size() const { return last - first + 1; }
  bool contains(Index v) const { return v >= first && v <= last; }
};

/// The kit: neutral mesh, parts, expressions.
struct IctKit {
  PolyMesh<> neutral;                          ///< all parts, V vertices
  std::map<std::string, VertexRange> regions;  ///< part name → its vertices
  std::vector<std::string> expression_names;   ///< E names (ARKit-style: jawOpen, mouthSmile_L, …)
  Eigen::MatrixXf deltas;                      ///< E × 3V: row e is expression e's displacement, x0 y0 z0 x1 …

  Index num_vertices() const { return neutral.num_vertices(); }

  /// The range of part `name`; ArgumentError listing the parts when there is none.
  const VertexRange& region(const std::string& name) const {
    const auto it = regions.find(name);
    if (it == regions.end()) {
      std::string known;
      for (const auto& [n, r] : regions) known += (known.empty() ? "" : ", ") + n;
      throw ArgumentError("ICT kit: no region '" + name + "' (regions: " + known + ")");
    }
    return it->second;
  }

  /// Index of expression `name`; ArgumentError when the kit has none of that name.
  Index expression_index(const std::string& name) const {
    const auto it = std::find(expression_names.begin(), expression_names.end(), name);
    if (it == expression_names.end()) throw ArgumentError("ICT kit: no expression '" + name + "'");
    return Index(it - expression_names.begin());
  }

  /// Expression `name`'s displacement of every vertex (V×3, cm).
  Points<> expression(const std::string& name) const {
    const Index e = expression_index(name);
    Points<> d(num_vertices(), 3);
    for (Index v = 0; v < num_vertices(); ++v)
      for (int c = 0; c < 3; ++c) d(v, c) = double(deltas(e, 3 * v + c));
    return d;
  }

  /// The faces whose corners all lie in the named parts, with the kit's vertex indices (V rows:
  /// vertices of other parts are simply unused).
  PolyMesh<> faces_within(const std::vector<std::string>& names) const {
    std::vector<const VertexRange*> ranges;
    for (const auto& n : names) ranges.push_back(&region(n));
    auto inside = [&](Index v) { return std::any_of(ranges.begin(), ranges.end(), [&](const VertexRange* r) { return r->contains(v); }); };
    PolyMesh<> out;
    out.V = neutral.V;
    std::vector<VIndex> corners;
    for (Index f = 0; f < neutral.num_faces(); ++f) {
      corners.assign(neutral.indices.begin() + neutral.offsets[std::size_t(f)], neutral.indices.begin() + neutral.offsets[std::size_t(f + 1)]);
      if (std::all_of(corners.begin(), corners.end(), [&](VIndex v) { return inside(v); })) out.add_face(corners);
    }
    return out;
  }
};

/// Reads the kit from `dir` (full_neutral.obj, regions.json, expressions_full.npz) and checks that
/// the files belong together: the ranges tile 0..V−1 without gap or overlap, `deltas` is E×V×3
/// with E names, every delta finite. ParseError / ArgumentError /
/// ShapeError naming the file and what is wrong otherwise.
inline IctKit read_ict_kit(const std::filesystem::path& dir) {
  IctKit kit;
  kit.neutral = io::read_obj<Scalar>(dir / "full_neutral.obj");
  const Index V = kit.neutral.num_vertices();

  const auto regions_file = dir / "regions.json";
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(io::read_text_file(regions_file));
  } catch (const nlohmann::json::exception& e) {
    throw ParseError(regions_file.string(), 0, e.what());
  }
  if (!j.contains("vertex_ranges_inclusive") || !j["vertex_ranges_inclusive"].is_object())
    throw ArgumentError(regions_file.string() + ": no object 'vertex_ranges_inclusive'");
  for (const auto& [name, r] : j["vertex_ranges_inclusive"].items()) {
    if (!r.is_array() || r.size() != 2 || !r[0].is_number_integer() || !r[1].is_number_integer())
      throw ArgumentError(regions_file.string() + ": region '" + name + "' must be [first, last] (integers)");
    const VertexRange range{r[0].get<Index>(), r[1].get<Index>()};
    if (range.first < 0 || range.last < range.first || range.last >= V)
      throw ArgumentError(regions_file.string() + ": region '" + name + "' = [" + std::to_string(range.first) + ", " +
                          std::to_string(range.last) + "] is not within the mesh's " + std::to_string(V) + " vertices");
    kit.regions[name] = range;
  }
  std::vector<std::pair<VertexRange, std::string>> sorted;
  for (const auto& [n, r] : kit.regions) sorted.push_back({r, n});
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first.first < b.first.first; });
  Index next = 0;
  for (const auto& [r, n] : sorted) {
    if (r.first != next)
      throw ArgumentError(regions_file.string() + ": region '" + n + "' starts at vertex " + std::to_string(r.first) + ", expected " +
                          std::to_string(next) + " (the ranges must tile the vertices without gap or overlap)");
    next = r.last + 1;
  }
  if (next != V)
    throw ArgumentError(regions_file.string() + ": the regions end at vertex " + std::to_string(next - 1) + ", the mesh has " + std::to_string(V));
  const auto expr_file = dir / "expressions_full.npz";
  const io::NpzArrays a = io::read_npz(expr_file);
  kit.expression_names = a.at("names").to_strings();
  const io::NpyArray& d = a.at("deltas");
  const std::int64_t E = std::int64_t(kit.expression_names.size());
  if (d.ndim() != 3 || d.shape[0] != E || d.shape[1] != V || d.shape[2] != 3)
    throw ShapeError(expr_file.string() + ": 'deltas' (names × vertices × 3)", std::vector<std::int64_t>{E, V, 3}, d.shape);
  const auto values = d.to_vector<float>();
  kit.deltas = Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(values.data(), E, 3 * V);
  if (!kit.deltas.allFinite()) throw ArgumentError(expr_file.string() + ": 'deltas' holds a non-finite value");
  return kit;
}

}  // namespace simsr::scenario
