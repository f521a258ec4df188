// libFuzzer harness for the .npy reader: any bytes must give an array or a simsr::Error; anything
// else (a crash, a sanitizer report, another exception type) is a finding.
#include <cstddef>
#include <cstdint>

#include <simsr/io/npy.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const simsr::io::NpyArray a = simsr::io::read_npy_buffer(data, size, "fuzz.npy");
    std::uint64_t n = 1;
    for (const auto d : a.shape) {
      if (d < 0) __builtin_trap();
      n *= static_cast<std::uint64_t>(d);
    }
    if (a.bytes.size() != n * a.dtype.itemsize) __builtin_trap();
    // Exercise the conversions on what was accepted (they may refuse lossy values).
    try {
      if (a.is_numeric()) {
        const auto v = a.to_vector<double>();
        if (v.size() != n) __builtin_trap();
        if (a.ndim() == 3 && a.shape[2] == 3 && a.shape[0] > 0) (void)a.frame_points<float>(a.shape[0] - 1);
        (void)a.to_vector<std::int64_t>();
      } else {
        if (a.to_strings().size() != n) __builtin_trap();
      }
    } catch (const simsr::Error&) {
    }
    // Whatever was read writes back to bytes that read back identically.
    const auto again = simsr::io::read_npy_buffer(simsr::io::npy_bytes(a), "rewritten.npy");
    if (again.bytes != a.bytes || again.shape != a.shape || !(again.dtype == a.dtype)) __builtin_trap();
  } catch (const simsr::Error&) {
  }
  return 0;
}
