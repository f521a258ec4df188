#pragma once
/// \file
/// Guards of a training step (issue #10: no silent failure): a non-finite loss, gradient or
/// weight stops training with a NumericalError naming the step and the tensor, before the
/// optimizer moves anything and before anything is saved.
///
///     const auto loss = model.loss_and_backward(policy, x, y, rng);
///     nn::require_finite_loss("β-VAE training", loss.total, adam.steps() + 1);
///     nn::require_finite_gradients("β-VAE training", store, adam.steps() + 1);
///     adam.step(policy);
///     nn::require_finite_parameters("β-VAE training", store, adam.steps());

#include <cmath>
#include <cstdint>
#include <string>

#include "../core/error.hpp"
#include "parameters.hpp"

namespace simsr::nn {

/// NumericalError unless `value` is finite.
inline void require_finite_loss(const std::string& where, double value, std::int64_t step) {
  if (!std::isfinite(value)) throw NumericalError(where, "the loss", step, value);
}

namespace detail {
template <class S, class Values>
void require_finite_entries(const std::string& where, const ParameterStore<S>& store, std::int64_t step, const char* what, Values&& values,
                            TensorEntry::Kind kind = TensorEntry::Kind::parameter) {
  for (const auto& e : store.entries()) {
    if (e.kind != kind) continue;
    const S* v = values(e);
    for (Index i = 0; i < e.size; ++i)
      if (!std::isfinite(double(v[i])))
        throw NumericalError(where, std::string(what) + " of '" + e.name + "' (entry " + std::to_string(i) + ")", step, double(v[i]));
  }
}
}  // namespace detail

/// NumericalError naming the first parameter tensor (and entry) whose gradient is not finite.
template <class S>
void require_finite_gradients(const std::string& where, const ParameterStore<S>& store, std::int64_t step) {
  detail::require_finite_entries(where, store, step, "the gradient", [&](const TensorEntry& e) { return store.gradients().data() + e.offset; });
}

/// NumericalError naming the first parameter tensor (and entry) whose value is not finite.
template <class S>
void require_finite_parameters(const std::string& where, const ParameterStore<S>& store, std::int64_t step) {
  detail::require_finite_entries(where, store, step, "the weight", [&](const TensorEntry& e) { return store.values().data() + e.offset; });
}

/// NumericalError naming the first buffer (BatchNorm running statistics) with a non-finite value.
template <class S>
void require_finite_buffers(const std::string& where, const ParameterStore<S>& store, std::int64_t step) {
  detail::require_finite_entries(
      where, store, step, "the buffer", [&](const TensorEntry& e) { return store.buffers().data() + e.offset; }, TensorEntry::Kind::buffer);
}

/// Every weight and buffer finite (what a model file or checkpoint may hold): before any write.
template <class S>
void require_finite_state(const std::string& where, const ParameterStore<S>& store, std::int64_t step = -1) {
  require_finite_parameters(where, store, step);
  require_finite_buffers(where, store, step);
}

}  // namespace simsr::nn
