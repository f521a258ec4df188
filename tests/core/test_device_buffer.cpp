#include <simsr/core/device_buffer.hpp>

#include <doctest/doctest.h>

#include <vector>

using namespace simsr;

TEST_CASE("Span and MatrixSpan: what a kernel body holds of an array, host memory alike") {
  std::vector<double> v{1, 2, 3, 4, 5, 6};
  const Span<double> s = span_of(v);
  CHECK(s.size == 6);
  s[2] = 30;
  CHECK(v[2] == 30);
  const Span<const double> r = s;  // read-only view of the same array
  CHECK(r.data == v.data());
  CHECK(r[2] == 30);
  const MatrixSpan<double> m{v.data(), 2, 3, 3};  // row-major 2×3
  CHECK(m(1, 0) == 4);
  m(0, 2) = -1;
  CHECK(v[2] == -1);
  const MatrixSpan<const double> strided{v.data(), 3, 1, 2};  // the first column of a 3×2
  CHECK(strided(2, 0) == 5);
  static_assert(std::is_trivially_copyable_v<Span<const float>> && std::is_trivially_copyable_v<MatrixSpan<double>>);
}
