#pragma once
/// \file
/// Flat storage of a network's trainable parameters, their gradients and its non-trainable
/// buffers, with PyTorch state-dict names (tiny-cuda-nn's flat buffers, §7 of the SPEC).
///
///     nn::ParameterStore<float> store;
///     nn::Linear<float> fc(store, "fc_out.0", 323, 384, rng, {.bias = false, .kernel_dims = 1});
///     for (const auto& e : store.entries()) save(e.name, e.shape, store.values(e));
///     store.zero_grad();  // before each backward pass
///     optimizer.step(exec::omp);   // Adam over store.parameters() / store.gradients()

#include <algorithm>
#include <numeric>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "tensor.hpp"

namespace simsr::nn {

/// One named tensor: `name` as in PyTorch's state_dict ("fc_out.0.weight"), `shape` as PyTorch
/// reports it (a Conv1d weight is {out, in, 1}; num_batches_tracked is a scalar, shape {}),
/// `offset` into the flat buffer of its kind, `size` = product of the shape.
struct TensorEntry {
  enum class Kind { parameter, buffer };
  std::string name;
  std::vector<Index> shape;
  Kind kind = Kind::parameter;
  Index offset = 0;
  Index size = 0;
};

/// Owns one flat value buffer and one matching gradient buffer for every trainable parameter,
/// and one flat buffer for the non-trainable buffers (BatchNorm running statistics).
///
/// Layers register their tensors at construction and keep the returned offsets; they take views
/// (Eigen::Map) at each call, so registering more tensors later never leaves a dangling view.
/// Entries keep registration order, which is PyTorch's state_dict order when layers register as
/// PyTorch modules do (weight, bias, then running_mean, running_var, num_batches_tracked).
/// num_batches_tracked (int64 in PyTorch) is stored as S: exact up to 2^24 steps in float.
template <class S = float>
class ParameterStore {
 public:
  using scalar_type = S;

  /// Registers a trainable tensor of the given shape (values 0, gradient 0); returns its offset
  /// in values()/gradients(). ArgumentError when the name is already taken or a size is negative.
  Index add_parameter(const std::string& name, std::vector<Index> shape) {
    return add(name, std::move(shape), TensorEntry::Kind::parameter);
  }
  /// Registers a non-trainable buffer (initial value `init`); returns its offset in buffers().
  Index add_buffer(const std::string& name, std::vector<Index> shape, S init = S(0)) {
    const Index off = add(name, std::move(shape), TensorEntry::Kind::buffer);
    std::fill(buffers_.begin() + off, buffers_.end(), init);
    return off;
  }

  /// Trainable values: PyTorch's sum(p.numel() for p in model.parameters()).
  Index num_parameters() const { return static_cast<Index>(values_.size()); }
  Index num_buffer_values() const { return static_cast<Index>(buffers_.size()); }

  /// All trainable values / their gradients / all buffer values, flat.
  VectorMap<S> values() { return VectorMap<S>(values_.data(), num_parameters()); }
  ConstVectorMap<S> values() const { return ConstVectorMap<S>(values_.data(), num_parameters()); }
  VectorMap<S> gradients() { return VectorMap<S>(gradients_.data(), num_parameters()); }
  ConstVectorMap<S> gradients() const { return ConstVectorMap<S>(gradients_.data(), num_parameters()); }
  VectorMap<S> buffers() { return VectorMap<S>(buffers_.data(), num_buffer_values()); }
  ConstVectorMap<S> buffers() const { return ConstVectorMap<S>(buffers_.data(), num_buffer_values()); }

  void zero_grad() { std::fill(gradients_.begin(), gradients_.end(), S(0)); }

  /// rows×cols views of a parameter's values / gradient / a buffer at `offset` (row-major).
  MatrixMap<S> value(Index offset, Index rows, Index cols) { return MatrixMap<S>(values_.data() + offset, rows, cols); }
  ConstMatrixMap<S> value(Index offset, Index rows, Index cols) const { return ConstMatrixMap<S>(values_.data() + offset, rows, cols); }
  MatrixMap<S> gradient(Index offset, Index rows, Index cols) { return MatrixMap<S>(gradients_.data() + offset, rows, cols); }
  ConstMatrixMap<S> gradient(Index offset, Index rows, Index cols) const { return ConstMatrixMap<S>(gradients_.data() + offset, rows, cols); }
  VectorMap<S> buffer(Index offset, Index size) { return VectorMap<S>(buffers_.data() + offset, size); }
  ConstVectorMap<S> buffer(Index offset, Index size) const { return ConstVectorMap<S>(buffers_.data() + offset, size); }

  /// Every tensor, parameters and buffers, in registration (state_dict) order.
  const std::vector<TensorEntry>& entries() const { return entries_; }
  /// The entry named `name`, or nullptr.
  const TensorEntry* find(const std::string& name) const {
    const auto it = index_.find(name);
    return it == index_.end() ? nullptr : &entries_[it->second];
  }
  /// The entry named `name`; ArgumentError naming it when absent.
  const TensorEntry& at(const std::string& name) const {
    if (const TensorEntry* e = find(name)) return *e;
    throw ArgumentError("nn::ParameterStore: no tensor named '" + name + "'");
  }

  /// The flat values of an entry (parameter values or buffer values, as its kind says).
  std::span<S> values(const TensorEntry& e) { return {base(e) + e.offset, static_cast<std::size_t>(e.size)}; }
  std::span<const S> values(const TensorEntry& e) const {
    return {const_cast<ParameterStore*>(this)->base(e) + e.offset, static_cast<std::size_t>(e.size)};
  }
  /// The flat gradient of a parameter entry (ArgumentError for a buffer).
  std::span<S> gradient(const TensorEntry& e) {
    if (e.kind != TensorEntry::Kind::parameter) throw ArgumentError("nn::ParameterStore: '" + e.name + "' is a buffer and has no gradient");
    return {gradients_.data() + e.offset, static_cast<std::size_t>(e.size)};
  }

 private:
  Index add(const std::string& name, std::vector<Index> shape, TensorEntry::Kind kind) {
    if (name.empty()) throw ArgumentError("nn::ParameterStore: a tensor needs a name");
    if (index_.count(name)) throw ArgumentError("nn::ParameterStore: tensor name '" + name + "' registered twice");
    Index size = 1;
    for (Index d : shape) {
      if (d < 0) throw ArgumentError("nn::ParameterStore: tensor '" + name + "' has a negative dimension");
      size *= d;
    }
    TensorEntry e{name, std::move(shape), kind, 0, size};
    if (kind == TensorEntry::Kind::parameter) {
      e.offset = num_parameters();
      values_.resize(values_.size() + static_cast<std::size_t>(size), S(0));
      gradients_.resize(values_.size(), S(0));
    } else {
      e.offset = num_buffer_values();
      buffers_.resize(buffers_.size() + static_cast<std::size_t>(size), S(0));
    }
    index_.emplace(e.name, entries_.size());
    entries_.push_back(std::move(e));
    return entries_.back().offset;
  }
  S* base(const TensorEntry& e) { return e.kind == TensorEntry::Kind::parameter ? values_.data() : buffers_.data(); }

  std::vector<S> values_, gradients_, buffers_;
  std::vector<TensorEntry> entries_;
  std::unordered_map<std::string, std::size_t> index_;
};

}  // namespace simsr::nn
