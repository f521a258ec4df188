#pragma once
// A coarse face model (HR ~10^4 tets, LR a few hundred), built once per test executable: the
// same code paths as the default model at a size the sanitizer builds can afford.
#include <simsr/scenario/face/face_model.hpp>

#include <filesystem>
#include <string>

#include <unistd.h>

#include "kit_fixture.hpp"

// SIMSR_TEST_SANITIZED: built with ASan or TSan (clang says so through __has_feature only).
#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define SIMSR_TEST_SANITIZED 1
#endif
#endif
#if !defined(SIMSR_TEST_SANITIZED) && (defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__))
#define SIMSR_TEST_SANITIZED 1
#endif

namespace simsr::test {

/// True when the kit and the tetgen program are there; otherwise reports what is missing
/// (SIMSR_MISSING: a failure where peers are required).
#define SIMSR_REQUIRE_FACE_INPUTS()                                              \
  do {                                                                           \
    if (!::simsr::test::have_ict_kit()) {                                        \
      SIMSR_MISSING("ICT kit not found in " << ::simsr::test::ict_kit_dir);      \
      return;                                                                    \
    }                                                                            \
    if (!::simsr::test::have_tetgen()) {                                         \
      SIMSR_MISSING("the tetgen program (apt-get install tetgen)");              \
      return;                                                                    \
    }                                                                            \
  } while (false)

inline scenario::FaceModelOptions coarse_face_options() {
  scenario::FaceModelOptions o;
  o.lr_cell = 2.0;
  o.skull_lattice = 1.6;
  o.hr.max_volume = 1.0;
  return o;
}

/// The coarse model (have_ict_kit() must be true and tetgen installed).
inline const scenario::FaceModel& coarse_face() {
  static const scenario::FaceModel face = [] {
    const auto dir = std::filesystem::temp_directory_path() / ("simsr_test_face_" + std::to_string(::getpid()));
    auto f = scenario::build_face_model(exec::omp, ict_kit(), coarse_face_options(), dir);
    std::filesystem::remove_all(dir);
    return f;
  }();
  return face;
}

}  // namespace simsr::test
