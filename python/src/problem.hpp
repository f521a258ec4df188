#pragma once
/// \file
/// simsr.UpsamplingProblem as the module holds it: the library's problem with the lock that
/// serializes what may write it. Fitting a method may compute the problem's neighbourhoods or LR
/// graph (interp::prepare, Learned::fit) with the GIL released, so two Python threads fitting on
/// one problem take turns; fits on different problems run side by side.
#include "common.hpp"

#include <memory>
#include <mutex>

#include <simsr/interp/fit_and_train.hpp>
#include <simsr/interp/problem.hpp>

namespace simsr::python {

struct Problem {
  interp::UpsamplingProblem<Scalar> problem;
  std::unique_ptr<std::mutex> mutex = std::make_unique<std::mutex>();
};

/// interp::prepare(policy, method, problem, k) with the GIL released, the method's and the
/// problem's locks held.
template <class I>
void fit_on(Problem& problem, I& method, std::mutex& method_mutex, Index neighborhood_k, const std::string& policy) {
  py::gil_scoped_release release;
  std::scoped_lock lock(method_mutex, *problem.mutex);
  with_policy(policy, [&](auto p) { interp::prepare(p, method, problem.problem, neighborhood_k); });
}

}  // namespace simsr::python
