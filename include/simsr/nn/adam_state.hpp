#pragma once
/// \file
/// Adam's state in a checkpoint file: the step count as "train/adam_step" and the two moments per
/// parameter tensor as "train/exp_avg/<name>" and "train/exp_avg_sq/<name>" (PyTorch's
/// optimizer state_dict keyed by the tensor's name), so a resumed run continues exactly. Shared
/// by nn::Trainer and the thin-shell training (shell/cloth_synthesis.hpp).
///
///     nn::add_adam_state(arrays, store, adam);                   // before io::write_npz
///     adam.load_state(nn::read_adam_state(arrays, store, file));  // after io::read_npz

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "../io/npz.hpp"
#include "adam.hpp"

namespace simsr::nn {

/// Adds `adam`'s state over `store`'s parameters to `out`. NumericalError for a non-finite moment
/// (a checkpoint that could not continue).
template <class S>
void add_adam_state(io::NpzArrays& out, const ParameterStore<S>& store, const Adam<S>& adam) {
  const auto& s = adam.state();
  const std::int64_t step = s.step;
  out["train/adam_step"] = io::make_npy<std::int64_t>({}, &step);
  if (s.exp_avg.size() != store.num_parameters()) return;  // before the first step: no moments yet
  for (Index i = 0; i < s.exp_avg.size(); ++i)
    if (!std::isfinite(double(s.exp_avg[i])) || !std::isfinite(double(s.exp_avg_sq[i])))
      throw NumericalError("nn::add_adam_state", "Adam's moment " + std::to_string(i), s.step, double(s.exp_avg[i]));
  for (const auto& e : store.entries()) {
    if (e.kind != TensorEntry::Kind::parameter) continue;
    std::vector<std::int64_t> shape(e.shape.begin(), e.shape.end());
    out["train/exp_avg/" + e.name] = io::make_npy<S>(shape, s.exp_avg.data() + e.offset);
    out["train/exp_avg_sq/" + e.name] = io::make_npy<S>(shape, s.exp_avg_sq.data() + e.offset);
  }
}

/// The state add_adam_state wrote, for `store`'s parameters. ArgumentError naming `file` for a
/// missing step or tensor, a negative step or a non-finite entry; ShapeError for a tensor of
/// another size.
template <class S>
typename Adam<S>::State read_adam_state(const io::NpzArrays& a, const ParameterStore<S>& store, const std::string& file) {
  if (!a.contains("train/adam_step")) throw ArgumentError(file + ": the checkpoint has no optimizer step 'train/adam_step'");
  typename Adam<S>::State s;
  s.step = a.at("train/adam_step").item<std::int64_t>();
  if (s.step < 0) throw ArgumentError(file + ": a negative optimizer step count");
  if (s.step == 0) return s;
  const Index n = store.num_parameters();
  s.exp_avg.setZero(n);
  s.exp_avg_sq.setZero(n);
  for (const auto& e : store.entries()) {
    if (e.kind != TensorEntry::Kind::parameter) continue;
    for (const auto& key : {"train/exp_avg/" + e.name, "train/exp_avg_sq/" + e.name})
      if (!a.contains(key)) throw ArgumentError(file + ": the checkpoint has no optimizer state '" + key + "'");
    const auto m = a.at("train/exp_avg/" + e.name).template to_vector<S>();
    const auto v = a.at("train/exp_avg_sq/" + e.name).template to_vector<S>();
    if (Index(m.size()) != e.size || Index(v.size()) != e.size)
      throw ShapeError(file + ": optimizer state of '" + e.name + "'", {e.size}, {Index(m.size())});
    for (std::size_t i = 0; i < m.size(); ++i)
      if (!std::isfinite(double(m[i])) || !std::isfinite(double(v[i])))
        throw ArgumentError(file + ": optimizer state of '" + e.name + "' entry " + std::to_string(i) + " is not finite");
    std::copy(m.begin(), m.end(), s.exp_avg.data() + e.offset);
    std::copy(v.begin(), v.end(), s.exp_avg_sq.data() + e.offset);
  }
  return s;
}

}  // namespace simsr::nn
