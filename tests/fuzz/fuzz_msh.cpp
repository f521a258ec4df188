// libFuzzer harness of the Gmsh .msh reader: any input must parse or throw simsr::Error; a parsed
// mesh must be well formed and survive a write/read round trip in both versions.
#include <cmath>
#include <cstdint>
#include <simsr/io/msh.hpp>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  simsr::io::MshMesh<double> m;
  try {
    m = simsr::io::read_msh(text, "fuzz.msh");
  } catch (const simsr::Error&) {
    return 0;
  }
  const auto nv = m.V.rows();
  if (static_cast<simsr::Index>(m.node_tags.size()) != nv) __builtin_trap();
  for (simsr::Index i = 0; i < m.V.size(); ++i)
    if (!std::isfinite(m.V.data()[i])) __builtin_trap();
  for (simsr::Index i = 0; i < m.T.size(); ++i)
    if (m.T.data()[i] < 0 || m.T.data()[i] >= nv) __builtin_trap();
  for (simsr::Index i = 0; i < m.F.size(); ++i)
    if (m.F.data()[i] < 0 || m.F.data()[i] >= nv) __builtin_trap();
  if (static_cast<simsr::Index>(m.tet_physical.size()) != m.T.rows() || static_cast<simsr::Index>(m.tet_entity.size()) != m.T.rows() ||
      static_cast<simsr::Index>(m.tri_physical.size()) != m.F.rows() || static_cast<simsr::Index>(m.tri_entity.size()) != m.F.rows())
    __builtin_trap();
  for (const auto& [type, count] : m.skipped)
    if (type == 2 || type == 4 || count <= 0) __builtin_trap();
  // 2.2 can express everything that was read; names with quotes cannot be written.
  bool quoted = false;
  for (const auto& p : m.physical_names) quoted |= p.name.find('"') != std::string::npos;
  if (quoted) return 0;
  const auto r = simsr::io::read_msh(simsr::io::format_msh(m, simsr::io::MshVersion::v22), "fuzz.msh");
  if (r.V != m.V || r.T != m.T || r.F != m.F || r.node_tags != m.node_tags || r.tet_physical != m.tet_physical ||
      r.tri_entity != m.tri_entity || r.physical_names != m.physical_names)
    __builtin_trap();
  try {
    const auto q = simsr::io::read_msh(simsr::io::format_msh(m, simsr::io::MshVersion::v41), "fuzz.msh");
    if (q.V != m.V || q.T.rows() != m.T.rows() || q.F.rows() != m.F.rows() || q.node_tags != m.node_tags) __builtin_trap();
  } catch (const simsr::ArgumentError&) {  // entity tag <= 0: not expressible in 4.1
  } catch (const simsr::MeshError&) {      // one entity, several physical tags
  }
  return 0;
}
