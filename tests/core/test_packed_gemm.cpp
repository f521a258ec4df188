#include <doctest/doctest.h>

#include <simsr/core/packed_gemm.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

using namespace simsr;

namespace {

/// Random shapes around the kernel's tile edges (MR rows, NR outputs), leading dimensions past the
/// widths, with and without a bias, accumulating or not, against a long-double loop.
template <class S>
void check_random_products(std::uint64_t seed) {
  const double eps = std::numeric_limits<S>::epsilon();
  using G = PackedGemm<S>;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto pick = [&](Index lo, Index hi) { return lo + Index(rng() % std::uint64_t(hi - lo + 1)); };
  for (int trial = 0; trial < 150; ++trial) {
    const Index rows = pick(0, 3 * G::MR + 1), in = pick(0, 70), out = pick(1, 3 * G::NR + 1);
    const Index ldx = in + pick(0, 3), ldy = out + pick(0, 3), ldw = in + pick(0, 2);
    const bool with_bias = rng() % 2, accumulate = rng() % 3 == 0;
    CAPTURE(trial);
    CAPTURE(rows);
    CAPTURE(in);
    CAPTURE(out);
    CAPTURE(accumulate);
    std::vector<S> x(std::size_t(std::max<Index>(rows * ldx, 1))), W(std::size_t(std::max<Index>(out * ldw, 1))), b(static_cast<std::size_t>(out)),
        y(std::size_t(rows * ldy));
    for (auto* v : {&x, &W, &b, &y})
      for (S& e : *v) e = S(u(rng));
    const std::vector<S> y0 = y;
    G g;
    g.pack(W.data(), out, in, ldw);
    typename G::Workspace ws;
    g.run(ws, rows, x.data(), ldx, with_bias ? b.data() : nullptr, y.data(), ldy, accumulate);
    for (Index r = 0; r < rows; ++r) {
      for (Index o = 0; o < out; ++o) {
        long double ref = accumulate ? y0[std::size_t(r * ldy + o)] : (with_bias ? b[std::size_t(o)] : 0);
        long double mag = std::abs(ref);
        for (Index d = 0; d < in; ++d) {
          ref += (long double)x[std::size_t(r * ldx + d)] * W[std::size_t(o * ldw + d)];
          mag += std::abs((long double)x[std::size_t(r * ldx + d)] * W[std::size_t(o * ldw + d)]);
        }
        CHECK(double(std::abs(y[std::size_t(r * ldy + o)] - ref)) <= eps * double(in + 2) * double(mag));  // the summation's worst-case bound
      }
      for (Index o = out; o < ldy; ++o) CHECK(y[std::size_t(r * ldy + o)] == y0[std::size_t(r * ldy + o)]);  // padding untouched
    }
    // any split of the rows gives the same bits (each entry depends on its row only)
    if (rows > 1) {
      std::vector<S> y2 = y0;
      const Index cut = pick(1, rows - 1);
      g.run(ws, cut, x.data(), ldx, with_bias ? b.data() : nullptr, y2.data(), ldy, accumulate);
      g.run(ws, rows - cut, x.data() + cut * ldx, ldx, with_bias ? b.data() : nullptr, y2.data() + cut * ldy, ldy, accumulate);
      CHECK(y2 == y);
    }
  }
}

}  // namespace

TEST_CASE("PackedGemm: y = b + x·Wᵀ against a long-double loop (random shapes, edges, strides, accumulation)") {
  check_random_products<float>(1);
  check_random_products<double>(2);
}

TEST_CASE("PackedGemm: a warm run allocates nothing new; bad shapes refused") {
  PackedGemm<float> g;
  std::vector<float> W(12 * 5, 0.5f), x(9 * 5, 1.0f), y(9 * 12);
  g.pack(W.data(), 12, 5, 5);
  CHECK(g.out_features() == 12);
  CHECK(g.in_features() == 5);
  PackedGemm<float>::Workspace ws;
  g.reserve(ws);
  const std::size_t cap = ws.buf.capacity();
  g.run(ws, 9, x.data(), 5, nullptr, y.data(), 12, false);
  CHECK(ws.buf.capacity() == cap);
  for (float v : y) CHECK(v == doctest::Approx(2.5f));
  CHECK_THROWS_AS(g.pack(W.data(), -1, 5, 5), ArgumentError);
  CHECK_THROWS_AS(g.pack(W.data(), 12, 5, 4), ArgumentError);  // a row shorter than the depth
}
