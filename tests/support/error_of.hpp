#pragma once
// The message of the simsr::Error that `f` throws ("" when it throws none): for checks that an
// error names what and where.
#include <simsr/core/error.hpp>

#include <string>
#include <utility>

namespace simsr::test {

/// The message of the exception of type E that `f` throws, "" when it throws none; an exception
/// of another type escapes (and fails the test): for checks that the error is the right type.
template <class E, class F>
std::string typed_error_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "";
}

/// typed_error_of for any simsr::Error.
template <class F>
std::string error_of(F&& f) {
  return typed_error_of<Error>(std::forward<F>(f));
}

}  // namespace simsr::test
