#pragma once
// The message of the simsr::Error that `f` throws ("" when it throws none): for checks that an
// error names what and where.
#include <simsr/core/error.hpp>

#include <string>

namespace simsr::test {

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace simsr::test
