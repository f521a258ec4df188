#include <doctest/doctest.h>

#include <simsr/eval/eval.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

using namespace simsr;

namespace {
std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace

TEST_CASE("statistics match a sort-based reference on random error sets") {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t n = 1 + rng() % 500;
    std::exponential_distribution<double> d(3.0 + trial % 7);
    std::vector<double> e(n);
    for (auto& x : e) x = d(rng);
    if (trial % 5 == 0) std::fill(e.begin(), e.begin() + long(n / 2), 0.25);  // many ties
    auto sorted = e;
    std::sort(sorted.begin(), sorted.end());
    const double median = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
    long double mean = 0;
    for (double x : e) mean += x;
    mean /= n;
    long double var = 0;
    for (double x : e) var += (x - mean) * (x - mean);
    const auto s = eval::statistics(e);
    CHECK(s.count == Index(n));
    CHECK(s.median == median);
    CHECK(s.min == sorted.front());
    CHECK(s.max == sorted.back());
    CHECK(s.mean == doctest::Approx(double(mean)).epsilon(1e-14));
    CHECK(s.std == doctest::Approx(std::sqrt(double(var / n))).epsilon(1e-12));
  }
  CHECK_THROWS_AS(eval::statistics({}), ArgumentError);
  CHECK_THROWS_AS(eval::statistics({1.0, std::nan("")}), ArgumentError);
}

TEST_CASE("vertex errors, diagonal, accumulator and relative statistics") {
  Points<> rest(3, 3), a(3, 3), b(3, 3);
  rest << 0, 0, 0, 3, 0, 0, 0, 4, 0;  // diagonal of the box [0,3]×[0,4]×[0,0] is 5
  a = rest;
  b = rest;
  b(0, 0) += 3;
  b(0, 1) += 4;  // vertex 0 off by 5, others exact
  CHECK(eval::bbox_diagonal(rest) == 5.0);
  const auto err = eval::vertex_errors(a, b);
  CHECK(err[0] == 5.0);
  CHECK(err[1] == 0.0);
  eval::ErrorAccumulator acc(rest);
  CHECK(acc.add_frame(a, b) == doctest::Approx(5.0 / 3));
  CHECK(acc.add_frame(a, a) == 0.0);
  CHECK(acc.num_frames() == 2);
  const auto s = acc.statistics();
  CHECK(s.count == 6);
  CHECK(s.max == 5.0);
  CHECK(s.median == 0.0);
  CHECK(acc.relative_statistics().max == doctest::Approx(1.0));
  CHECK_THROWS_AS(acc.add_frame(Points<>(2, 3), Points<>(2, 3)), ShapeError);
  Points<> bad = a;
  bad(1, 1) = std::nan("");
  CHECK_THROWS_AS(acc.add_frame(bad, a), ArgumentError);
}

TEST_CASE("normalized_to_largest: the worst method reads 1 in every column") {
  std::vector<eval::ErrorStatistics> m{{1, 2, 3, 4, 0.5, 10}, {2, 1, 6, 2, 0.25, 10}};
  const auto n = eval::normalized_to_largest(m);
  CHECK(n[0].mean == 0.5);
  CHECK(n[1].mean == 1.0);
  CHECK(n[0].median == 1.0);
  CHECK(n[1].std == 1.0);
  CHECK(n[0].max == 1.0);
  CHECK(n[1].min == 0.5);
}

TEST_CASE("report files: frame CSV, statistics CSV, SVG plot") {
  const std::filesystem::path dir = SIMSR_TEST_TMP_DIR;
  std::filesystem::create_directories(dir);
  eval::write_frame_csv(dir / "frames.csv", {{"embedded", {0.5, 0.25}}, {"mls, deg 2", {1, 2}}}, {10, 11});
  CHECK(slurp(dir / "frames.csv") == "frame,embedded,\"mls, deg 2\"\n10,0.5,1\n11,0.25,2\n");
  CHECK_THROWS_AS(eval::write_frame_csv(dir / "x.csv", {{"a", {1}}, {"b", {1, 2}}}), ShapeError);
  eval::write_statistics_csv(dir / "stats.csv", {"a", "b"}, {{1, 1, 1, 1, 1, 4}, {2, 2, 2, 2, 2, 4}}, 2.0);
  const auto stats = slurp(dir / "stats.csv");
  CHECK(stats.find("a,4,1,1,1,1,1,0.5,0.5,0.5,0.5,0.5,0.5,0.5,0.5,0.5,0.5\n") != std::string::npos);
  CHECK(stats.find("b,4,2,2,2,2,2,1,1,1,1,1,1,1,1,1,1\n") != std::string::npos);
  eval::write_svg_plot(dir / "plot.svg", {{"a<b", {0, 1, 2}}, {"c", {2, 1, 0}}}, "errors & frames", "mean error");
  const auto svg = slurp(dir / "plot.svg");
  CHECK(svg.rfind("<svg", 0) == 0);
  CHECK(svg.find("a&lt;b") != std::string::npos);
  CHECK(svg.find("errors &amp; frames") != std::string::npos);
  std::size_t lines = 0;
  for (std::size_t p = svg.find("<polyline"); p != std::string::npos; p = svg.find("<polyline", p + 1)) ++lines;
  CHECK(lines == 2);
  CHECK_THROWS_AS(eval::write_frame_csv("/nonexistent-dir/x.csv", {{"a", {1}}}), ParseError);
}
