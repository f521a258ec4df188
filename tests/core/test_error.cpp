#include <doctest/doctest.h>

#include <simsr/core/error.hpp>

using namespace simsr;

TEST_CASE("errors say what and where, and share one base") {
  try {
    throw ParseError("mesh.msh", 42, "expected 4 node tags, got 3");
  } catch (const Error& e) {
    CHECK(std::string(e.what()) == "mesh.msh:42: expected 4 node tags, got 3");
  }
  ParseError binary("a.npy", 0, "truncated at byte 80");
  CHECK(std::string(binary.what()) == "a.npy: truncated at byte 80");
  CHECK(binary.line() == 0);
  MeshError m("tet", 17, "inverted (signed volume -0.5)");
  CHECK(std::string(m.what()) == "tet 17: inverted (signed volume -0.5)");
  CHECK(m.element() == 17);
  ShapeError s("lowres", {-1, 1747, 3}, {256, 1746, 3});
  CHECK(std::string(s.what()) == "lowres: expected shape (*, 1747, 3), got (256, 1746, 3)");
  ConvergenceError c("newton", 50, 1e-3);
  CHECK(c.iterations() == 50);
  CHECK(std::string(c.what()).find("50 iterations") != std::string::npos);
  static_assert(std::is_base_of_v<std::runtime_error, Error>);
}
