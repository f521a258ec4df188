#include <doctest/doctest.h>

#include <simsr/core/types.hpp>

using namespace simsr;

// ConstPointsRef / PointsRef: what per-frame calls (interp's apply) take so that callers' own
// buffers — a NumPy array through the Python module among them — are read and written in place.
namespace {
double first_x(const ConstPointsRef<>& p) { return p(0, 0); }
const double* address(const ConstPointsRef<>& p) { return p.data(); }
void scale_into(const ConstPointsRef<>& in, PointsRef<> out) { out = 2.0 * in; }
}  // namespace

TEST_CASE("ConstPointsRef reads contiguous row-major rows in place and copies any other layout") {
  Points<> P = Points<>::Random(7, 3);
  CHECK(address(P) == P.data());
  CHECK(address(P.middleRows(2, 3)) == P.row(2).data());  // a row block: still stride 3
  Eigen::Map<const Points<>> map(P.data() + 3, 4, 3);
  CHECK(address(map) == P.data() + 3);
  const Eigen::MatrixXd column_major = P;  // another layout: Eigen copies it into the Ref's temporary
  CHECK(address(column_major) != column_major.data());
  CHECK(first_x(column_major) == P(0, 0));
  const Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> wide = Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>::Random(5, 4);
  CHECK(address(wide.leftCols<3>()) != wide.data());  // row stride 4: copied
  CHECK(first_x(wide.leftCols<3>()) == wide(0, 0));
}

TEST_CASE("PointsRef writes the caller's buffer in place: a Points, a row block, a Map") {
  const Points<> P = Points<>::Random(6, 3);
  Points<> out = Points<>::Zero(6, 3);
  scale_into(P, out);
  CHECK(out.isApprox(2.0 * P));
  double buffer[18] = {};
  scale_into(P, Eigen::Map<Points<>>(buffer, 6, 3));
  CHECK(buffer[17] == 2.0 * P(5, 2));
  Points<> big = Points<>::Zero(10, 3);
  scale_into(P, big.middleRows(2, 6));
  CHECK(big.row(1).isZero());
  CHECK(big.middleRows(2, 6).isApprox(2.0 * P));
  CHECK(big.row(8).isZero());
}
