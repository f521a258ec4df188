// libFuzzer harness for the .npz reader (libzip from memory, then the .npy parser per member): any
// bytes must give arrays or a simsr::Error; anything else is a finding.
// Inputs starting with "SIMSRWRAP" are not archives: the remaining bytes become one member of a
// freshly written zip (stored or deflated by the next byte), so mutations reach the .npy-in-zip
// streaming path instead of stopping at the CRC check.
#include <zip.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include <simsr/io/npz.hpp>

namespace {

std::vector<std::byte> wrap(const std::uint8_t* data, std::size_t size, bool deflate) {
  zip_error_t err;
  zip_error_init(&err);
  zip_source_t* out = zip_source_buffer_create(nullptr, 0, 0, &err);
  zip_error_fini(&err);
  if (!out) return {};
  zip_source_keep(out);
  zip_t* z = zip_open_from_source(out, ZIP_TRUNCATE, nullptr);
  std::vector<std::byte> bytes;
  if (z) {
    zip_source_t* member = zip_source_buffer(z, data, size, 0);
    const zip_int64_t idx = member ? zip_file_add(z, "m.npy", member, 0) : -1;
    if (idx < 0 && member) zip_source_free(member);
    if (idx >= 0) zip_set_file_compression(z, static_cast<zip_uint64_t>(idx), deflate ? ZIP_CM_DEFLATE : ZIP_CM_STORE, 0);
    if (zip_close(z) != 0) zip_discard(z);
    zip_stat_t st;
    zip_stat_init(&st);
    if (zip_source_open(out) == 0) {
      if (zip_source_stat(out, &st) == 0 && (st.valid & ZIP_STAT_SIZE)) {
        bytes.resize(st.size);
        if (zip_source_read(out, bytes.data(), st.size) != static_cast<zip_int64_t>(st.size)) bytes.clear();
      }
      zip_source_close(out);
    }
  }
  zip_source_free(out);
  return bytes;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static constexpr char tag[] = "SIMSRWRAP";
  std::vector<std::byte> wrapped;
  if (size > sizeof(tag) && std::memcmp(data, tag, sizeof(tag) - 1) == 0) {
    wrapped = wrap(data + sizeof(tag), size - sizeof(tag), (data[sizeof(tag) - 1] & 1) != 0);
    if (wrapped.empty()) return 0;
    data = reinterpret_cast<const std::uint8_t*>(wrapped.data());
    size = wrapped.size();
  }
  try {
    simsr::io::NpzReader z(data, size, "fuzz.npz");
    z.set_max_member_bytes(std::uint64_t{1} << 26);
    for (const auto& name : z.names()) {
      try {
        const simsr::io::NpyArray a = z.read(name);
        std::uint64_t n = 1;
        for (const auto d : a.shape) n *= static_cast<std::uint64_t>(d);
        if (a.bytes.size() != n * a.dtype.itemsize) __builtin_trap();
        // No member may hold more than deflate's 1032:1 expansion of the whole input.
        if (a.bytes.size() > 1032 * size + 1024) __builtin_trap();
        if (a.is_numeric()) {
          try {
            (void)a.to_vector<double>();
          } catch (const simsr::Error&) {
          }
        }
      } catch (const simsr::Error&) {
      }
    }
  } catch (const simsr::Error&) {
  }
  return 0;
}
