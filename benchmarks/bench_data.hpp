#pragma once
// Where the benchmarks find the bundled data (the bunny, the ICT face): SIMSR_DATA_DIR from CMake,
// else ../shared/data beside the repository.
#include <filesystem>

inline std::filesystem::path data_dir() {
#ifdef SIMSR_DATA_DIR
  return std::filesystem::path(SIMSR_DATA_DIR);
#else
  return std::filesystem::path(__FILE__).parent_path() / ".." / ".." / "shared" / "data";
#endif
}
