#pragma once
// The bundled ICT kit, read once per test executable (each read parses ~8 MB of OBJ and npz).
#include <simsr/scenario/face/ict_kit.hpp>

#include <cstdlib>
#include <filesystem>
#include <memory>

namespace simsr::test {

inline const std::filesystem::path ict_kit_dir = std::filesystem::path(SIMSR_DATA_DIR) / "ict_face";

inline bool have_ict_kit() {
  return std::filesystem::exists(ict_kit_dir / "full_neutral.obj") && std::filesystem::exists(ict_kit_dir / "expressions_full.npz") &&
         std::filesystem::exists(ict_kit_dir / "regions.json");
}

/// Debian's tetgen program on the PATH (the HR mesher the scenario runs).
inline bool have_tetgen() { return std::system("command -v tetgen > /dev/null 2>&1") == 0; }

/// The kit (have_ict_kit() must be true).
inline const scenario::IctKit& ict_kit() {
  static const scenario::IctKit kit = scenario::read_ict_kit(ict_kit_dir);
  return kit;
}

}  // namespace simsr::test
