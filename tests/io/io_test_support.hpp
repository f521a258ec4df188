#pragma once
// Shared by the io tests: the fixtures folder, what the peers recorded for each fixture, and the
// check that a reader throws ParseError at the right file and line.
#include <doctest/doctest.h>

#include <simsr/core/error.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

namespace simsr::test {

inline const std::filesystem::path io_data_dir = std::filesystem::path(SIMSR_TEST_DATA_DIR) / "io";

/// A number recorded by tests/data/io/make_expected.py (meshio/numpy) for `file`: `key` (a
/// '/'-separated path into nested objects, e.g. "element_types/4"), or element `index` of it.
inline double expected(const std::string& file, const std::string& key, int index = -1) {
  static const nlohmann::json json = [] {
    std::ifstream in(io_data_dir / "expected.json");
    REQUIRE(in);
    return nlohmann::json::parse(in);
  }();
  REQUIRE(json.contains(file));
  const nlohmann::json* v = &json.at(file);
  for (std::size_t b = 0, e; b <= key.size(); b = e + 1) {
    e = std::min(key.find('/', b), key.size());
    const std::string part = key.substr(b, e - b);
    REQUIRE_MESSAGE(v->contains(part), file, ": no '", key, "' in expected.json");
    v = &v->at(part);
  }
  return index >= 0 ? v->at(std::size_t(index)).get<double>() : v->get<double>();
}

/// Runs `f`, which must throw simsr::ParseError naming `file` (any when empty) and `line`, with
/// `part` in its message.
inline void expect_parse_error(const std::function<void()>& f, const std::string& file, std::int64_t line, const std::string& part) {
  bool thrown = false;
  try {
    f();
  } catch (const simsr::ParseError& e) {
    thrown = true;
    INFO(std::string(e.what()));
    if (!file.empty()) CHECK(e.file() == file);
    CHECK(e.line() == line);
    CHECK(std::string(e.what()).find(part) != std::string::npos);
  }
  CHECK_MESSAGE(thrown, "no ParseError for: ", part);
}

}  // namespace simsr::test
