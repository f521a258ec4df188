#pragma once
// A check that needs something outside the library (a peer such as numpy, scipy or meshio, the
// bundled ../shared/data, a glibc feature) and cannot find it: where SIMSR_REQUIRE_PEERS is set to
// anything but "0" (scripts/test.sh and .ci/run set it to 1), that is a failure naming what is
// missing; elsewhere the test case reports the skip and returns. Use it as the statement before the
// test case's `return`:
//
//   if (!std::filesystem::exists(dir / "train_frames.npz")) {
//     SIMSR_MISSING("bunny data not found in " << dir);
//     return;
//   }
#include <doctest/doctest.h>

#include <cstdlib>
#include <cstring>

namespace simsr::test {

/// True where a missing peer or data folder must fail the test (SIMSR_REQUIRE_PEERS set, not "0").
inline bool peers_required() {
  const char* v = std::getenv("SIMSR_REQUIRE_PEERS");
  return v != nullptr && *v != '\0' && std::strcmp(v, "0") != 0;
}

}  // namespace simsr::test

/// FAIL (SIMSR_REQUIRE_PEERS set) or MESSAGE "...: skipped" (otherwise); `what` is a doctest
/// message expression (`"scipy not found for " << python`).
#define SIMSR_MISSING(what)                                                                   \
  do {                                                                                        \
    if (::simsr::test::peers_required())                                                      \
      FAIL(what << " (SIMSR_REQUIRE_PEERS is set: a missing peer or data folder is a failure)"); \
    else                                                                                      \
      MESSAGE(what << ": skipped (set SIMSR_REQUIRE_PEERS=1 to make this a failure)");        \
  } while (0)
