#include "material_checks.hpp"

#include <simsr/core/error.hpp>

using namespace simsr::physics;

namespace {
// Composite Simpson rule.
template <class Fn>
double simpson(Fn f, double a, double b, int n = 2000) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4 : 2) * f(a + i * h);
  return s * h / 3;
}

template <class C>
void check_curve(const C& c, double lo, double hi, const std::vector<double>& breaks) {
  const double h = 1e-6;
  for (double l = lo; l <= hi; l += 0.0137) {
    CAPTURE(l);
    bool near_break = false;
    for (double b : breaks) near_break |= std::abs(l - b) < 1e-4;
    if (!near_break) {
      CHECK(c.derivative(l) == doctest::Approx((c.value(l + h) - c.value(l - h)) / (2 * h)).epsilon(1e-6).scale(1.0));
      CHECK(c.value(l) == doctest::Approx((c.energy(l + h) - c.energy(l - h)) / (2 * h)).epsilon(1e-6).scale(1.0));
    }
    // Antiderivative from λ = 1 against quadrature (split at the breakpoints, where the curve is smooth).
    std::vector<double> knots{std::min(1.0, l), std::max(1.0, l)};
    for (double b : breaks)
      if (b > knots.front() && b < knots.back()) knots.push_back(b);
    std::sort(knots.begin(), knots.end());
    double q = 0;
    for (std::size_t i = 0; i + 1 < knots.size(); ++i)
      q += simpson([&](double s) { return c.value(s); }, knots[i], knots[i + 1]);
    CHECK(c.energy(l) == doctest::Approx(l >= 1 ? q : -q).epsilon(1e-10).scale(1.0));
  }
}

// Value continuous at b; slopes from both sides are returned.
template <class C>
std::pair<double, double> one_sided_slopes(const C& c, double b) {
  const double e = 1e-9;
  CHECK(c.value(b - e) == doctest::Approx(c.value(b + e)).epsilon(1e-7).scale(1.0));
  return {c.derivative(b - e), c.derivative(b + e)};
}
}  // namespace

TEST_CASE("passive fibre curve (Blemker 2005): values, C1 at lambda*, energy") {
  const PassiveFibreCurve<> p;
  CHECK(p.value(0.5) == 0.0);
  CHECK(p.value(1.0) == 0.0);
  CHECK(p.energy(0.7) == 0.0);
  CHECK(p.value(1.2) == doctest::Approx(0.05 * (std::exp(6.6 * 0.2) - 1)));
  const auto [l, r] = one_sided_slopes(p, 1.4);
  CHECK(l == doctest::Approx(r).epsilon(1e-7));
  const auto [l1, r1] = one_sided_slopes(p, 1.0);  // Blemker's curve: C0 only at λ = 1
  CHECK(l1 == 0.0);
  CHECK(r1 == doctest::Approx(0.05 * 6.6).epsilon(1e-6));
  check_curve(p, 0.5, 2.2, {1.0, 1.4});
  CHECK_THROWS_AS((PassiveFibreCurve<>{0.05, 6.6, 1.0}.check()), simsr::ArgumentError);
  CHECK_THROWS_AS((PassiveFibreCurve<>{-0.05, 6.6, 1.4}.check()), simsr::ArgumentError);
  CHECK_THROWS_AS((PassiveFibreCurve<>{0.05, 0.0, 1.4}.check()), simsr::ArgumentError);
}

TEST_CASE("active force-length curve: support [0.4, 1.6], peak 1, C1 everywhere, energy") {
  for (double ofl : {1.0, 0.9, 1.15}) {
    CAPTURE(ofl);
    const ActiveFibreCurve<> a{ofl};
    CHECK(a.value(ofl) == doctest::Approx(1.0));
    CHECK(a.derivative(ofl) == doctest::Approx(0.0).scale(1.0));
    CHECK(a.value(0.39 * ofl) == 0.0);
    CHECK(a.value(1.61 * ofl) == 0.0);
    CHECK(a.value(0.5 * ofl) > 0.0);
    CHECK(a.energy(1.0) == 0.0);
    for (double x : {0.4, 7.0 / 12, 17.0 / 12, 1.6}) {
      const auto [l, r] = one_sided_slopes(a, x * ofl);
      CHECK(l == doctest::Approx(r).epsilon(1e-6).scale(1.0));
    }
    // Close to Blemker's piecewise quadratic (9(x−0.4)², 1 − 4(x−1)², 9(x−1.6)²).
    for (double x = 0.4; x <= 1.6; x += 0.001) {
      const double blemker = x < 0.6 ? 9 * (x - 0.4) * (x - 0.4)
                             : x <= 1.4 ? 1 - 4 * (x - 1) * (x - 1)
                                        : 9 * (x - 1.6) * (x - 1.6);
      CHECK(std::abs(a.value(x * ofl) - blemker) < 5e-3);
    }
    check_curve(a, 0.2, 1.9, {0.4 * ofl, 7.0 / 12 * ofl, 17.0 / 12 * ofl, 1.6 * ofl});
  }
  CHECK_THROWS_AS((ActiveFibreCurve<>{0.0}.check()), simsr::ArgumentError);
}
