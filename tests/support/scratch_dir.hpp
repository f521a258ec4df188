#pragma once
// A scratch directory under the system's temporary directory, named after the test and the
// process (parallel ctest runs never share one), emptied at the start and removed at the end.
#include <unistd.h>

#include <filesystem>
#include <string>

namespace simsr::test {

struct ScratchDir {
  std::filesystem::path path;
  explicit ScratchDir(const std::string& name) : path(std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  ~ScratchDir() { std::filesystem::remove_all(path); }
};

}  // namespace simsr::test
