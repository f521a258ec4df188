// libFuzzer harness for the .npz reader (libzip from memory, then the .npy parser per member): any
// bytes must give arrays or a simsr::Error; anything else is a finding.
#include <cstddef>
#include <cstdint>

#include <simsr/io/npz.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    simsr::io::NpzReader z(data, size, "fuzz.npz");
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
