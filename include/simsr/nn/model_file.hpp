#pragma once
/// \file
/// A trained network as one self-contained `.npz` (SPEC §7 "Weights are saved as .npz"): every
/// tensor under its PyTorch state-dict name and shape (float32; `num_batches_tracked` int64 0-d),
/// the config as 0-d unicode JSON, and everything inference needs — rest shapes, LR tets, HR
/// faces, neighbourhoods, normalization (and the residual base: the Embedded matrix `embedding_*`, or
/// the local-linear map `residual_map_*`, both as scipy CSR arrays). The layout is
/// the one scripts/torch_to_simsr.py writes from an official PyTorch checkpoint, so either loads.
///
///     nn::ModelData data = nn::read_model_data("model.npz");         // config + geometry
///     nn::SuperResolutionNet<float> net(data.config, data.geometry, rng);
///     nn::load_state(net.store(), nn::read_model_arrays("model.npz"));  // strict, as PyTorch's
///     nn::save_model("copy.npz", net, data);

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <algorithm>

#include "../io/npz.hpp"
#include "finite_checks.hpp"
#include "super_resolution_net.hpp"

namespace simsr::nn {

/// What a model file holds besides the weights.
struct ModelData {
  NetworkConfig config;
  NetworkGeometry geometry;
  Tets lr_tets;   ///< T×4 LR tetrahedra (the simulation mesh)
  Tris hr_faces;  ///< F×3 HR surface triangles
};

/// Module prefixes of state-dict tensors (everything else in the file is data).
inline bool is_state_tensor_name(const std::string& name) {
  for (const char* p : {"net_feat_emb.", "net_upscale.", "net_decoder."})
    if (name.rfind(p, 0) == 0) return true;
  return false;
}

/// The state dict of `store` as npz arrays: parameters and buffers in S (float32 for the default
/// float network, as PyTorch's; a double network keeps its precision), num_batches_tracked as
/// int64 (PyTorch's dtype).
template <class S>
void add_state(io::NpzArrays& out, const ParameterStore<S>& store) {
  for (const auto& e : store.entries()) {
    const auto v = store.values(e);
    std::vector<std::int64_t> shape(e.shape.begin(), e.shape.end());
    const bool counter = e.name.ends_with(".num_batches_tracked");
    if (counter) {
      std::vector<std::int64_t> c(v.size());
      for (std::size_t i = 0; i < v.size(); ++i) c[i] = static_cast<std::int64_t>(v[i]);
      out[e.name] = io::make_npy<std::int64_t>(shape, c.data());
    } else {
      out[e.name] = io::make_npy<S>(shape, v.data());
    }
  }
}

/// Copies the state tensors of `arrays` into `store`, strictly: every tensor of the store must be
/// present with its exact shape, and no state tensor (module prefix) may be left over — a
/// ShapeError / ArgumentError names the tensor. Non-finite values are rejected.
template <class S>
void load_state(ParameterStore<S>& store, const io::NpzArrays& arrays) {
  for (const auto& e : store.entries()) {
    if (!arrays.contains(e.name)) throw ArgumentError("nn::load_state: the model file has no tensor '" + e.name + "'");
    const io::NpyArray& a = arrays.at(e.name);
    std::vector<Index> shape(a.shape.begin(), a.shape.end());
    if (shape != e.shape) {
      auto text = [](const std::vector<Index>& s) {
        std::string t = "(";
        for (std::size_t i = 0; i < s.size(); ++i) t += (i ? ", " : "") + std::to_string(s[i]);
        return t + ")";
      };
      throw ArgumentError("nn::load_state: tensor '" + e.name + "' has shape " + text(shape) + ", the network expects " + text(e.shape));
    }
    const std::vector<S> v = a.to_vector<S>();
    auto dst = store.values(e);
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!std::isfinite(double(v[i])))
        throw ArgumentError("nn::load_state: tensor '" + e.name + "' entry " + std::to_string(i) + " is not finite");
      dst[i] = v[i];
    }
  }
  for (const auto& [name, a] : arrays)
    if (is_state_tensor_name(name) && !store.find(name))
      throw ArgumentError("nn::load_state: the model file has tensor '" + name + "', which this network does not have");
}

namespace detail {

template <class T>
Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> model_matrix(const io::NpzArrays& a, const std::string& file,
                                                                                 const std::string& name, Index cols) {
  if (!a.contains(name)) throw ArgumentError(file + ": the model file has no array '" + name + "'");
  const io::NpyArray& x = a.at(name);
  if (x.ndim() != 2 || (cols >= 0 && x.shape[1] != cols))
    throw ShapeError(file + ": array '" + name + "'", {-1, cols}, {x.ndim() > 0 ? Index(x.shape[0]) : 0, x.ndim() > 1 ? Index(x.shape[1]) : 0});
  return x.to_matrix<T>();
}

/// A rows×cols sparse matrix stored as `<name>_indptr`, `<name>_indices`, `<name>_data` (scipy's
/// CSR), checked: consistent lengths, indptr never decreasing, indices within [0, cols), finite values.
inline Eigen::SparseMatrix<double, Eigen::RowMajor> read_csr(const io::NpzArrays& a, const std::string& file, const std::string& name, Index rows,
                                                            Index cols) {
  for (const char* part : {"_indptr", "_indices", "_data"})
    if (!a.contains(name + part)) throw ArgumentError(file + ": '" + name + part + "' is missing (the " + name + " CSR arrays come together)");
  const auto ptr = a.at(name + "_indptr").to_vector<std::int64_t>();
  const auto idx = a.at(name + "_indices").to_vector<std::int64_t>();
  const auto val = a.at(name + "_data").to_vector<double>();
  if (Index(ptr.size()) != rows + 1 || ptr.front() != 0 || std::size_t(ptr.back()) != idx.size() || idx.size() != val.size())
    throw ArgumentError(file + ": the " + name + " CSR arrays are inconsistent (" + std::to_string(rows) + " rows expected)");
  // all of indptr before any row is read: a row past a later decrease would index beyond idx
  for (Index r = 0; r < rows; ++r)
    if (ptr[std::size_t(r + 1)] < ptr[std::size_t(r)]) throw ArgumentError(file + ": " + name + "_indptr decreases at row " + std::to_string(r));
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(idx.size());
  for (Index r = 0; r < rows; ++r) {
    for (auto k = ptr[std::size_t(r)]; k < ptr[std::size_t(r + 1)]; ++k) {
      if (idx[std::size_t(k)] < 0 || idx[std::size_t(k)] >= cols) throw ArgumentError(file + ": " + name + " index out of range in row " + std::to_string(r));
      if (!std::isfinite(val[std::size_t(k)])) throw ArgumentError(file + ": " + name + " entry in row " + std::to_string(r) + " is not finite");
      t.emplace_back(r, idx[std::size_t(k)], val[std::size_t(k)]);
    }
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor> m(rows, cols);
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

inline void write_csr(io::NpzArrays& out, const std::string& name, Eigen::SparseMatrix<double, Eigen::RowMajor> m) {
  m.makeCompressed();
  std::vector<std::int64_t> ptr(m.outerIndexPtr(), m.outerIndexPtr() + m.rows() + 1), idx(m.innerIndexPtr(), m.innerIndexPtr() + m.nonZeros());
  out[name + "_indptr"] = io::make_npy<std::int64_t>({std::int64_t(ptr.size())}, ptr.data());
  out[name + "_indices"] = io::make_npy<std::int64_t>({std::int64_t(idx.size())}, idx.data());
  out[name + "_data"] = io::make_npy<double>({std::int64_t(m.nonZeros())}, m.valuePtr());
}

}  // namespace detail

/// ArgumentError unless `arrays` hold exactly the state tensors that `cfg` implies for M HR
/// vertices (SuperResolutionNet::state_shapes), each with its shape: checked on the arrays' headers
/// before any network is built, so a small file cannot make the loader allocate a huge network.
inline void check_state_shapes(const io::NpzArrays& arrays, const std::string& file, const NetworkConfig& cfg, Index M) {
  auto text = [](const auto& shape) {
    std::string t = "(";
    for (std::size_t i = 0; i < shape.size(); ++i) t += (i ? ", " : "") + std::to_string(shape[i]);
    return t + ")";
  };
  const std::vector<TensorEntry> expected = SuperResolutionNet<float>::state_shapes(cfg, M);
  for (const auto& e : expected) {
    if (!arrays.contains(e.name)) throw ArgumentError(file + ": the config implies tensor '" + e.name + "' " + text(e.shape) + ", which the file lacks");
    const auto& shape = arrays.at(e.name).shape;
    if (std::vector<Index>(shape.begin(), shape.end()) != e.shape)
      throw ArgumentError(file + ": tensor '" + e.name + "' has shape " + text(shape) + ", the config implies " + text(e.shape));
  }
  for (const auto& [name, a] : arrays)
    if (is_state_tensor_name(name) &&
        std::none_of(expected.begin(), expected.end(), [&, &n = name](const TensorEntry& e) { return e.name == n; }))
      throw ArgumentError(file + ": tensor '" + name + "' is not part of the network its config describes");
}

/// Config, geometry, tets and faces of a model file's arrays; `file` names it in errors. The
/// config is validated (every field within its bounds) and the state tensors' shapes checked
/// against it (check_state_shapes) before anything the config sizes is allocated.
inline ModelData model_data(const io::NpzArrays& a, const std::string& file = "<model>") {
  ModelData d;
  if (!a.contains("config")) throw ArgumentError(file + ": the model file has no 'config'");
  const auto cfg_text = a.at("config").to_strings();
  if (cfg_text.size() != 1) throw ArgumentError(file + ": 'config' must be one JSON string");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(cfg_text[0]);
  } catch (const nlohmann::json::exception& e) {
    throw ParseError(file + ":config", 0, e.what());
  }
  d.config = NetworkConfig::from_json(j);
  if (a.contains("norm_mean")) d.config.norm_mean = a.at("norm_mean").item<double>();
  if (a.contains("norm_std")) d.config.norm_std = a.at("norm_std").item<double>();
  d.config.validate();
  auto& g = d.geometry;
  g.lr_rest = detail::model_matrix<double>(a, file, "lr_rest", 3);
  g.hr_rest = detail::model_matrix<double>(a, file, "hr_rest", 3);
  check_state_shapes(a, file, d.config, g.hr_rest.rows());
  g.lr_graph = detail::model_matrix<VIndex>(a, file, "lr_graph", -1);
  g.up_indices = detail::model_matrix<VIndex>(a, file, "up_indices", -1);
  g.up_distances = detail::model_matrix<double>(a, file, "up_distances", -1);
  d.lr_tets = detail::model_matrix<VIndex>(a, file, "lr_tets", 4);
  d.hr_faces = detail::model_matrix<VIndex>(a, file, "hr_faces", 3);
  const Index N = g.lr_rest.rows(), M = g.hr_rest.rows();
  if (g.lr_graph.rows() != N) throw ShapeError(file + ": 'lr_graph' (N rows)", {N, -1}, {g.lr_graph.rows(), g.lr_graph.cols()});
  if (g.up_indices.rows() != M || g.up_distances.rows() != M || g.up_distances.cols() != g.up_indices.cols())
    throw ShapeError(file + ": 'up_indices'/'up_distances' (M×upK)", {M, g.up_indices.cols()}, {g.up_distances.rows(), g.up_distances.cols()});
  auto check_range = [&](const auto& m, Index n, const char* what) {
    for (Index i = 0; i < m.size(); ++i)
      if (m.data()[i] < 0 || m.data()[i] >= n)
        throw ArgumentError(file + ": '" + what + "' entry " + std::to_string(i) + " = " + std::to_string(m.data()[i]) + " is outside [0, " +
                            std::to_string(n) + ")");
  };
  check_range(g.lr_graph, N, "lr_graph");
  check_range(g.up_indices, N, "up_indices");
  check_range(d.lr_tets, N, "lr_tets");
  check_range(d.hr_faces, M, "hr_faces");
  if (a.contains("embedding_indptr")) {
    g.embedding = detail::read_csr(a, file, "embedding", M, N);
  } else if (d.config.residual && d.config.residual_base == ResidualBase::embedded) {
    throw ArgumentError(file + ": a residual model needs the embedding arrays (embedding_indptr, embedding_indices, embedding_data)");
  }
  if (a.contains("residual_map_indptr")) {
    g.residual_map = detail::read_csr(a, file, "residual_map", 3 * M, 3 * N);
  } else if (d.config.residual && d.config.residual_base == ResidualBase::local_linear) {
    throw ArgumentError(file + ": a model over the local-linear base needs its arrays (residual_map_indptr, residual_map_indices, residual_map_data)");
  }
  return d;
}

/// Everything in a model file (weights and data).
inline io::NpzArrays read_model_arrays(const std::filesystem::path& path) { return io::read_npz(path); }
inline ModelData read_model_data(const std::filesystem::path& path) { return model_data(io::read_npz(path), path.string()); }

/// The model file's arrays for `net` and its data (which must be the data `net` was built from).
/// NumericalError when a weight or buffer of `net` is not finite: a model file never holds one.
template <class S, class Search>
io::NpzArrays model_arrays(const SuperResolutionNet<S, Search>& net, const ModelData& data) {
  require_finite_state("nn::save_model", net.store());
  io::NpzArrays out;
  add_state(out, net.store());
  out["config"] = io::make_npy(std::vector<std::string>{net.config().to_json().dump()});
  out["config"].shape.clear();  // 0-d, as np.array(json_text)
  const auto& g = data.geometry;
  auto i64 = [](const auto& m) { return Eigen::Matrix<std::int64_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>(m.template cast<std::int64_t>()); };
  out["lr_rest"] = io::make_npy(g.lr_rest);
  out["lr_tets"] = io::make_npy(i64(data.lr_tets));
  out["hr_rest"] = io::make_npy(g.hr_rest);
  out["hr_faces"] = io::make_npy(i64(data.hr_faces));
  out["lr_graph"] = io::make_npy(i64(g.lr_graph));
  out["up_indices"] = io::make_npy(i64(g.up_indices));
  out["up_distances"] = io::make_npy(g.up_distances);
  const double mean = net.config().norm_mean, sd = net.config().norm_std;
  out["norm_mean"] = io::make_npy<double>({}, &mean);
  out["norm_std"] = io::make_npy<double>({}, &sd);
  if (g.embedding.nonZeros() > 0) detail::write_csr(out, "embedding", g.embedding);
  if (g.residual_map.nonZeros() > 0) detail::write_csr(out, "residual_map", g.residual_map);
  return out;
}

template <class S, class Search>
void save_model(const std::filesystem::path& path, const SuperResolutionNet<S, Search>& net, const ModelData& data) {
  io::write_npz(path, model_arrays(net, data));
}

}  // namespace simsr::nn
