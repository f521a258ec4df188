// eval::intersecting_pairs_per_frame (the lip-intersection count beside Table 1): against a
// brute-force loop over every pair with the exact triangle test, on random frames of two
// crumpled sheets; seq == omp; the quantum keeps coordinates in the exact test's range; bad input
// is named.
#include <simsr/eval/intersections.hpp>

#include <doctest/doctest.h>

#include <cmath>
#include <random>

using namespace simsr;

namespace {

/// Two n×n sheets, b at z = 0 and a at z = 0.3, both on [0, 1]²; frame f moves every vertex by
/// noise of amplitude `amp`, so some frames cross and some do not.
struct Sheets {
  ContactPatches patches;
  Index m = 0;
};

Sheets sheets(Index n) {
  Sheets s;
  s.m = 2 * n * n;
  const Index cells = (n - 1) * (n - 1);
  s.patches.a.resize(2 * cells, 3);
  s.patches.b.resize(2 * cells, 3);
  Index t = 0;
  for (Index j = 0; j + 1 < n; ++j)
    for (Index i = 0; i + 1 < n; ++i, t += 2) {
      const VIndex v = VIndex(j * n + i), o = VIndex(n * n);
      s.patches.b.row(t) << v, v + 1, VIndex(v + n + 1);
      s.patches.b.row(t + 1) << v, VIndex(v + n + 1), VIndex(v + n);
      s.patches.a.row(t) << o + v, VIndex(o + v + n + 1), o + v + 1;
      s.patches.a.row(t + 1) << o + v, VIndex(o + v + n), VIndex(o + v + n + 1);
    }
  return s;
}

data::FrameMatrix<> random_frames(std::mt19937& rng, Index n, Index frames, double scale) {
  std::uniform_real_distribution<double> u(-1, 1), amp(0, 0.4);
  data::FrameMatrix<> X(frames, 3 * 2 * n * n);
  for (Index f = 0; f < frames; ++f) {
    const double a = amp(rng);
    for (Index k = 0; k < 2; ++k)
      for (Index j = 0; j < n; ++j)
        for (Index i = 0; i < n; ++i) {
          const Index v = k * n * n + j * n + i;
          X(f, 3 * v) = scale * (double(i) / double(n - 1) + 0.02 * u(rng));
          X(f, 3 * v + 1) = scale * (double(j) / double(n - 1) + 0.02 * u(rng));
          X(f, 3 * v + 2) = scale * (0.3 * double(k) + a * u(rng));
        }
  }
  return X;
}

std::int64_t brute_force(const data::FrameMatrix<>& X, Index f, const ContactPatches& p, double quantum) {
  auto at = [&](VIndex v) { return Vec3<double>(X(f, 3 * v), X(f, 3 * v + 1), X(f, 3 * v + 2)); };
  std::int64_t count = 0;
  for (Index i = 0; i < p.a.rows(); ++i)
    for (Index j = 0; j < p.b.rows(); ++j)
      count += triangles_intersect(at(p.a(i, 0)), at(p.a(i, 1)), at(p.a(i, 2)), at(p.b(j, 0)), at(p.b(j, 1)), at(p.b(j, 2)), quantum);
  return count;
}

}  // namespace

TEST_CASE("eval::intersecting_pairs_per_frame: the brute-force count of every frame, at any scale, seq == omp") {
  std::mt19937 rng(4);
  const Index n = 6;
  const Sheets s = sheets(n);
  for (const double scale : {1e-3, 1.0, 250.0}) {
    const auto X = random_frames(rng, n, 24, scale);
    const auto counts = eval::intersecting_pairs_per_frame(exec::seq, X, s.patches);
    CHECK(counts == eval::intersecting_pairs_per_frame(exec::omp, X, s.patches));
    Index crossing = 0, apart = 0;
    for (Index f = 0; f < X.rows(); ++f) {
      const double q = eval::intersection_quantum(X.row(f).cwiseAbs().maxCoeff());
      CHECK(counts[std::size_t(f)] == brute_force(X, f, s.patches, q));
      (counts[std::size_t(f)] > 0 ? crossing : apart) += 1;
    }
    CHECK(crossing > 3);  // the random frames cover both cases
    CHECK(apart > 3);
    const auto sum = eval::summarize_intersections(counts);
    CHECK(sum.frames == 24);
    CHECK(sum.frames_with_intersections == crossing);
    std::int64_t total = 0, most = 0;
    for (auto c : counts) total += c, most = std::max(most, c);
    CHECK(sum.pairs_total == total);
    CHECK(sum.pairs_max == most);
  }
}

TEST_CASE("eval::intersection_quantum keeps |x| within 2^37 quanta, the finest power of two that does") {
  for (const double x : {1e-9, 0.3, 1.0, 2.0, 3.999, 1e6}) {
    const double q = eval::intersection_quantum(x);
    CHECK(x / q <= 0x1p37);
    CHECK(x / (q / 2) >= 0x1p37);
    CHECK(std::ldexp(1.0, std::ilogb(q)) == q);
  }
  CHECK_THROWS_AS(eval::intersection_quantum(std::nan("")), ArgumentError);
}

TEST_CASE("eval::intersecting_pairs_per_frame: bad input is named") {
  const Sheets s = sheets(3);
  data::FrameMatrix<> X = data::FrameMatrix<>::Zero(2, 3 * s.m);
  X(1, 4) = std::nan("");
  CHECK_THROWS_WITH_AS(eval::intersecting_pairs_per_frame(exec::seq, X, s.patches), doctest::Contains("frame 1 has a non-finite position"), ArgumentError);
  CHECK_THROWS_WITH_AS(eval::intersecting_pairs_per_frame(exec::seq, data::FrameMatrix<>::Zero(2, 3 * s.m - 3), s.patches),
                       doctest::Contains("outside [0, 17)"), ArgumentError);
  CHECK_THROWS_AS(eval::intersecting_pairs_per_frame(exec::seq, data::FrameMatrix<>::Zero(2, 7), s.patches), ArgumentError);
}
