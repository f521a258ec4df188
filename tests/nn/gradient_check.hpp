#pragma once
/// \file
/// Shared checks of the nn tests: central finite differences (double) of a random scalar loss
/// Σ r⊙out against backward, for the input and every trainable parameter; seq vs omp bitwise;
/// warm calls allocate nothing (malloc counted by test_allocation.cpp).

#include <simsr/nn/nn.hpp>

#include <doctest/doctest.h>

#include "../support/allocation_check.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace simsr::test {

using nn::Matrix;

inline Matrix<double> random_matrix(std::mt19937_64& rng, Index rows, Index cols, double lo = -1, double hi = 1) {
  std::uniform_real_distribution<double> u(lo, hi);
  Matrix<double> m(rows, cols);
  for (Index i = 0; i < m.size(); ++i) m.data()[i] = u(rng);
  return m;
}

/// Entries of magnitude in [gap, 1] with random signs: away from LeakyReLU's kink.
inline Matrix<double> random_away_from_zero(std::mt19937_64& rng, Index rows, Index cols, double gap = 0.05) {
  Matrix<double> m = random_matrix(rng, rows, cols, gap, 1);
  std::bernoulli_distribution flip(0.5);
  for (Index i = 0; i < m.size(); ++i)
    if (flip(rng)) m.data()[i] = -m.data()[i];
  return m;
}

/// Max-norm relative error of one gradient block ("input" or a parameter's name).
struct GradientError {
  std::string what;
  double rel_error = 0;  ///< max|analytic − numeric| / max(max|analytic|, max|numeric|)
  double scale = 0;      ///< max|analytic|: a zero gradient would make the check vacuous
};

inline GradientError compare(const std::string& what, const std::vector<double>& a, const std::vector<double>& n) {
  double diff = 0, sa = 0, sn = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = std::max(diff, std::abs(a[i] - n[i]));
    sa = std::max(sa, std::abs(a[i]));
    sn = std::max(sn, std::abs(n[i]));
  }
  const double s = std::max(sa, sn);
  return {what, s > 0 ? diff / s : diff, sa};
}

/// fwd(x, out) and bwd(x, out, d_out, d_x*) of some composition of layers whose parameters live
/// in `store` (may be null). Buffers (BatchNorm running statistics) are restored before every
/// forward, so the loss is a function of x and the parameters only.
template <class Fwd, class Bwd>
std::vector<GradientError> gradient_check(Matrix<double> x, nn::ParameterStore<double>* store, Fwd&& fwd, Bwd&& bwd, std::mt19937_64& rng,
                                          bool check_input = true, double h = 1e-6) {
  const nn::Vector<double> buffers = store ? nn::Vector<double>(store->buffers()) : nn::Vector<double>();
  auto restore = [&] {
    if (store) store->buffers() = buffers;
  };
  Matrix<double> out, dx;
  restore();
  fwd(x, out);
  const Matrix<double> r = random_matrix(rng, out.rows(), out.cols());
  if (store) store->zero_grad();
  bwd(x, out, r, check_input ? &dx : nullptr);
  auto loss = [&] {
    Matrix<double> o;
    restore();
    fwd(x, o);
    return (o.array() * r.array()).sum();
  };
  auto numeric = [&](double& v) {
    const double v0 = v;
    v = v0 + h;
    const double lp = loss();
    v = v0 - h;
    const double lm = loss();
    v = v0;
    return (lp - lm) / (2 * h);
  };
  std::vector<GradientError> errors;
  if (check_input) {
    std::vector<double> a(dx.data(), dx.data() + dx.size()), n;
    for (Index i = 0; i < x.size(); ++i) n.push_back(numeric(x.data()[i]));
    errors.push_back(compare("input", a, n));
  }
  if (store) {
    const nn::Vector<double> grads = store->gradients();
    for (const auto& e : store->entries()) {
      if (e.kind != nn::TensorEntry::Kind::parameter) continue;
      std::vector<double> a(grads.data() + e.offset, grads.data() + e.offset + e.size), n;
      for (Index i = 0; i < e.size; ++i) n.push_back(numeric(store->values()[e.offset + i]));
      errors.push_back(compare(e.name, a, n));
    }
  }
  restore();
  return errors;
}

/// Every block within `tol` and with a nonzero gradient.
inline void check_gradients(const std::vector<GradientError>& errors, double tol = 1e-6) {
  REQUIRE(!errors.empty());
  for (const auto& e : errors) {
    INFO(e.what << ": relative error " << e.rel_error << ", gradient scale " << e.scale);
    CHECK(e.rel_error < tol);
    CHECK(e.scale > 0);
  }
}

/// check_gradients for networks with attention: the key projections' biases (names ending in
/// ".k.bias") have an exactly zero gradient, since softmax is invariant to a constant added to a
/// query's scores and q·(k_j + b_k) adds q·b_k to all of them; they are checked to be ~0 instead.
inline void check_attention_gradients(const std::vector<GradientError>& errors, double tol = 1e-6) {
  std::vector<GradientError> rest;
  for (const auto& e : errors) {
    if (e.what.size() > 7 && e.what.compare(e.what.size() - 7, 7, ".k.bias") == 0) {
      INFO(e.what << ": gradient scale " << e.scale);
      CHECK(e.scale < 1e-12);
    } else {
      rest.push_back(e);
    }
  }
  check_gradients(rest, tol);
}

/// The same layer checked on its own (forward/backward with `mode`).
template <nn::Layer L>
std::vector<GradientError> layer_gradient_check(L& layer, nn::ParameterStore<double>* store, const Matrix<double>& x, nn::Mode mode,
                                                std::mt19937_64& rng) {
  return gradient_check(
      x, store, [&](const Matrix<double>& in, Matrix<double>& out) { layer.forward(exec::seq, mode, in, out); },
      [&](const Matrix<double>& in, const Matrix<double>& out, const Matrix<double>& d, Matrix<double>* dx) {
        layer.backward(exec::seq, in, out, d, dx);
      },
      rng);
}

template <class A, class B>
bool bitwise_equal(const A& a, const B& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && std::equal(a.data(), a.data() + a.size(), b.data());
}

/// forward + backward under exec::seq and exec::omp from the same state: outputs, input
/// gradients, parameter gradients and buffers must agree bit for bit.
template <nn::Layer L, class S>
void check_seq_equals_omp(L& layer, nn::ParameterStore<S>* store, const Matrix<S>& x, nn::Mode mode, std::mt19937_64& rng) {
  const nn::Vector<S> buffers0 = store ? nn::Vector<S>(store->buffers()) : nn::Vector<S>();
  Matrix<S> out1, dx1, out2, dx2;
  if (store) store->zero_grad();
  layer.forward(exec::seq, mode, x, out1);
  const Matrix<S> r = random_matrix(rng, out1.rows(), out1.cols()).template cast<S>();
  layer.backward(exec::seq, x, out1, r, &dx1);
  nn::Vector<S> grads1, buffers1;
  if (store) grads1 = store->gradients(), buffers1 = store->buffers(), store->buffers() = buffers0, store->zero_grad();
  layer.forward(exec::omp, mode, x, out2);
  layer.backward(exec::omp, x, out2, r, &dx2);
  CHECK(bitwise_equal(out1, out2));
  CHECK(bitwise_equal(dx1, dx2));
  if (store) {
    CHECK(bitwise_equal(grads1, nn::Vector<S>(store->gradients())));
    CHECK(bitwise_equal(buffers1, nn::Vector<S>(store->buffers())));
  }
}

/// A second forward + backward of the same shapes under `policy` calls malloc zero times and
/// keeps the output and input-gradient buffers.
template <exec::HostPolicy Policy, nn::Layer L, class S>
void check_warm_no_allocation(Policy policy, L& layer, const Matrix<S>& x, nn::Mode mode) {
  Matrix<S> out, dx;
  layer.forward(policy, mode, x, out);
  const Matrix<S> r = Matrix<S>::Ones(out.rows(), out.cols());
  layer.backward(policy, x, out, r, &dx);
  const S* out_ptr = out.data();
  const S* dx_ptr = dx.data();
  const long before = simsr_test_malloc_count();
  layer.forward(policy, mode, x, out);
  layer.backward(policy, x, out, r, &dx);
  SIMSR_CHECK_NO_ALLOCATION(policy, simsr_test_malloc_count() - before);
  CHECK(out.data() == out_ptr);
  CHECK(dx.data() == dx_ptr);
}

}  // namespace simsr::test
