// libFuzzer harness of the OBJ reader: any input must parse or throw simsr::Error; a parsed mesh
// must be well formed, read back identically after writing, and tet soups must give valid tets.
#include <cmath>
#include <cstdint>
#include <simsr/io/obj.hpp>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  simsr::PolyMesh<double> m;
  try {
    m = simsr::io::read_obj(text, "fuzz.obj");
  } catch (const simsr::Error&) {
    return 0;
  }
  if (m.offsets.empty() || m.offsets.front() != 0 || m.offsets.back() != static_cast<simsr::Index>(m.indices.size())) __builtin_trap();
  for (simsr::Index f = 0; f < m.num_faces(); ++f)
    if (m.face_size(f) < 3) __builtin_trap();
  for (auto i : m.indices)
    if (i < 0 || i >= m.num_vertices()) __builtin_trap();
  for (simsr::Index i = 0; i < m.V.size(); ++i)
    if (!std::isfinite(m.V.data()[i])) __builtin_trap();
  const auto again = simsr::io::read_obj(simsr::io::format_obj(m), "fuzz.obj");  // must not throw
  if (again.V != m.V || again.indices != m.indices || again.offsets != m.offsets) __builtin_trap();
  if (simsr::io::is_tet_soup(m)) {
    const auto t = simsr::io::read_obj_tets(text, "fuzz.obj");
    if (t.T.rows() * 4 != m.num_faces()) __builtin_trap();
    for (simsr::Index r = 0; r < t.T.rows(); ++r)
      for (int a = 0; a < 4; ++a) {
        if (t.T(r, a) < 0 || t.T(r, a) >= t.V.rows()) __builtin_trap();
        for (int b = a + 1; b < 4; ++b)
          if (t.T(r, a) == t.T(r, b)) __builtin_trap();
      }
    if (simsr::io::read_obj_tets(simsr::io::format_obj_tets(t), "fuzz.obj").T != t.T) __builtin_trap();
  } else {
    try {
      simsr::io::read_obj_tets(text, "fuzz.obj");
      __builtin_trap();  // read_obj_tets must agree with is_tet_soup
    } catch (const simsr::ParseError&) {
    }
  }
  (void)simsr::triangulate(m);
  return 0;
}
