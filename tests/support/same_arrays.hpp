#pragma once
// Two .npz archives hold the same arrays: the same names, and each array's dtype, shape and bytes
// equal, except the arrays named in `skip` (wall-clock `seconds`, which two runs cannot share).
// For the checks that a run split over shards or ranks writes the whole run's files bitwise.
#include <doctest/doctest.h>

#include <simsr/io/npz.hpp>

#include <filesystem>
#include <set>
#include <string>

namespace simsr::test {

inline void check_same_arrays(const io::NpzArrays& a, const io::NpzArrays& b, const std::set<std::string>& skip = {"seconds"}) {
  CHECK(a.names() == b.names());
  for (const auto& entry : a) {  // no structured binding: clang 14 cannot CAPTURE one
    const std::string& name = entry.first;
    CAPTURE(name);
    if (skip.count(name) != 0) continue;
    REQUIRE(b.contains(name));
    CHECK(entry.second.dtype.descr() == b.at(name).dtype.descr());
    CHECK(entry.second.shape == b.at(name).shape);
    CHECK(entry.second.bytes == b.at(name).bytes);
  }
}

inline void check_same_arrays(const std::filesystem::path& a, const std::filesystem::path& b, const std::set<std::string>& skip = {"seconds"}) {
  CAPTURE(a);
  check_same_arrays(io::read_npz(a), io::read_npz(b), skip);
}

}  // namespace simsr::test
