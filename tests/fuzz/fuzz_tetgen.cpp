// libFuzzer harness of the TetGen reader. The input holds the three files separated by "@@":
// node@@ele[@@face] (no second "@@": no .face). Any input must parse or throw simsr::Error; a
// parsed mesh must be well formed and survive a write/read round trip.
#include <cmath>
#include <cstdint>
#include <optional>
#include <simsr/io/tetgen.hpp>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto a = text.find("@@");
  if (a == std::string_view::npos) return 0;
  const auto b = text.find("@@", a + 2);
  const std::string_view node = text.substr(0, a);
  const std::string_view ele = text.substr(a + 2, b == std::string_view::npos ? std::string_view::npos : b - a - 2);
  const std::optional<std::string_view> face = b == std::string_view::npos ? std::nullopt : std::optional(text.substr(b + 2));
  simsr::io::TetgenMesh<double> m;
  try {
    m = simsr::io::read_tetgen(node, ele, face, "fuzz");
  } catch (const simsr::Error&) {
    return 0;
  }
  const auto nv = m.V.rows();
  if (m.first_index != 0 && m.first_index != 1) __builtin_trap();
  for (simsr::Index i = 0; i < m.V.size(); ++i)
    if (!std::isfinite(m.V.data()[i])) __builtin_trap();
  for (simsr::Index i = 0; i < m.T.size(); ++i)
    if (m.T.data()[i] < 0 || m.T.data()[i] >= nv) __builtin_trap();
  for (simsr::Index i = 0; i < m.tet_edge_nodes.size(); ++i)
    if (m.tet_edge_nodes.data()[i] < 0 || m.tet_edge_nodes.data()[i] >= nv) __builtin_trap();
  for (simsr::Index i = 0; i < m.F.size(); ++i)
    if (m.F.data()[i] < 0 || m.F.data()[i] >= nv) __builtin_trap();
  if (m.node_attributes.rows() != nv || m.tet_attributes.rows() != m.T.rows()) __builtin_trap();
  if (!m.node_markers.empty() && static_cast<simsr::Index>(m.node_markers.size()) != nv) __builtin_trap();
  if (m.has_faces != face.has_value()) __builtin_trap();
  const auto t = simsr::io::format_tetgen(m);
  const auto r = simsr::io::read_tetgen(t.node, t.ele, m.has_faces ? std::optional<std::string_view>(t.face) : std::nullopt, "fuzz");
  if (r.V != m.V || r.T != m.T || r.F != m.F || r.first_index != m.first_index || r.node_markers != m.node_markers ||
      r.face_markers != m.face_markers || r.tet_edge_nodes.size() != m.tet_edge_nodes.size())
    __builtin_trap();
  if (m.node_attributes.size() && r.node_attributes != m.node_attributes) __builtin_trap();
  return 0;
}
