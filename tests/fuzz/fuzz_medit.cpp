// libFuzzer harness of the MEDIT .mesh reader: any input must parse or throw simsr::Error; a
// parsed mesh must be well formed and survive a write/read round trip.
#include <cmath>
#include <cstdint>
#include <simsr/io/medit.hpp>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  simsr::io::MeditMesh<double> m;
  try {
    m = simsr::io::read_medit(text, "fuzz.mesh");
  } catch (const simsr::Error&) {
    return 0;
  }
  const auto nv = m.V.rows();
  for (simsr::Index i = 0; i < m.V.size(); ++i)
    if (!std::isfinite(m.V.data()[i])) __builtin_trap();
  for (simsr::Index i = 0; i < m.T.size(); ++i)
    if (m.T.data()[i] < 0 || m.T.data()[i] >= nv) __builtin_trap();
  for (simsr::Index i = 0; i < m.F.size(); ++i)
    if (m.F.data()[i] < 0 || m.F.data()[i] >= nv) __builtin_trap();
  if (static_cast<simsr::Index>(m.vertex_refs.size()) != nv || static_cast<simsr::Index>(m.tri_refs.size()) != m.F.rows() ||
      static_cast<simsr::Index>(m.tet_refs.size()) != m.T.rows())
    __builtin_trap();
  for (const auto& [kw, n] : m.skipped)
    if (n < 0) __builtin_trap();
  const auto r = simsr::io::read_medit(simsr::io::format_medit(m), "fuzz.mesh");
  if (r.V != m.V || r.T != m.T || r.F != m.F || r.vertex_refs != m.vertex_refs || r.tri_refs != m.tri_refs || r.tet_refs != m.tet_refs)
    __builtin_trap();
  return 0;
}
