#pragma once
// `simsr neighbors --lr-rest L --hr-rest H --k 20 --out N.npz`: the §3.2 upsampling
// neighbourhoods (LR→HR one-to-one assignment + k-label Dijkstra over the HR surface) and the LR
// geodesic graph (EdgeConv's first graph: Dijkstra over LR mesh edges, self first).
#include <simsr/io/mesh_io.hpp>
#include <simsr/io/npz.hpp>
#include <simsr/neighbors/geodesic_knn.hpp>
#include <simsr/neighbors/upsampling_neighborhoods.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <memory>
#include <string>

namespace simsr::cli {

/// The LR rest volume mesh (any tet format, or the official 4-triangles-per-tet OBJ).
inline TetMesh<double> read_lr_rest(const std::string& file) {
  auto m = io::read_mesh(file);
  if (m.T.rows() == 0) throw ArgumentError(file + ": the LR rest shape must be a tet mesh (it has no tets)");
  return {std::move(m.V), std::move(m.T)};
}

/// The HR rest surface (any triangle format; a tet mesh gives its boundary is not accepted:
/// the HR vertex order must be the frames' order).
inline TriMesh<double> read_hr_rest(const std::string& file) {
  auto m = io::read_mesh(file);
  if (m.F.rows() == 0) throw ArgumentError(file + ": the HR rest shape must be a triangle surface (it has no triangles)");
  return {std::move(m.V), std::move(m.F)};
}

struct NeighborsArgs {
  std::string lr, hr, out;
  Index k = 20, lr_k = 0;
};

inline int neighbors_cmd(const NeighborsArgs& a) {
  using clock = std::chrono::steady_clock;
  const auto lr = read_lr_rest(a.lr);
  const auto hr = read_hr_rest(a.hr);
  const auto t0 = clock::now();
  neighbors::UpsamplingOptions opt;
  opt.k = a.k;
  const auto nb = neighbors::upsampling_neighborhoods(exec::omp, lr.V, hr.V, hr.F, opt);
  const auto t1 = clock::now();
  const Index lr_k = a.lr_k > 0 ? a.lr_k : a.k;
  const auto graph = neighbors::geodesic_knn(exec::omp, lr.V, lr.T, lr_k);
  const auto t2 = clock::now();
  io::NpzArrays z = neighbors::upsampling_neighborhoods_arrays(nb);
  z["lr_indices"] = io::make_npy(graph.indices.cast<std::int64_t>().eval());
  z["lr_distances"] = io::make_npy(graph.distances);
  io::write_npz(a.out, z, io::NpzCompression::Deflate);
  const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  nlohmann::ordered_json j;
  j["lr_vertices"] = lr.V.rows();
  j["hr_vertices"] = hr.V.rows();
  j["k"] = a.k;
  j["assignment_cost"] = nb.assignment_cost;
  j["assignment_globally_optimal"] = nb.assignment_globally_optimal;
  j["upsampling_ms"] = ms(t1 - t0);
  j["lr_graph_ms"] = ms(t2 - t1);
  std::cout << j.dump() << '\n';
  return 0;
}

inline void add_neighbors(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("neighbors", "Upsampling neighbourhoods (§3.2) and the LR geodesic graph, saved as .npz");
  auto a = std::make_shared<NeighborsArgs>();
  cmd->add_option("--lr-rest", a->lr, "LR rest tet mesh (.msh .node/.ele .mesh, or OBJ with 4 triangles per tet)")->required();
  cmd->add_option("--hr-rest", a->hr, "HR rest surface (.obj .msh .mesh)")->required();
  cmd->add_option("--k", a->k, "LR neighbours per HR vertex (paper: 20)")->check(CLI::PositiveNumber);
  cmd->add_option("--lr-k", a->lr_k, "neighbours per LR vertex in the LR geodesic graph (default: --k)");
  cmd->add_option("--out", a->out, "output .npz: indices, distances (M×k), lr_to_hr, lr_indices, lr_distances (N×lr-k)")->required();
  cmd->callback([&action, a] { action = [a] { return neighbors_cmd(*a); }; });
}

}  // namespace simsr::cli
