#pragma once
// `simsr neighbors --lr-rest L --hr-rest H --k 20 --out N.npz`: the §3.2 upsampling
// neighbourhoods (LR→HR one-to-one assignment + k-label Dijkstra over the HR surface) and the LR
// geodesic graph (EdgeConv's first graph: Dijkstra over LR mesh edges, self first).
#include <simsr/data/network_neighborhoods.hpp>
#include <simsr/data/rest_shapes.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <memory>
#include <string>

namespace simsr::cli {

struct NeighborsArgs {
  std::string lr, hr, out;
  Index k = 20, lr_k = 0;
};

inline int neighbors_cmd(const NeighborsArgs& a) {
  const auto lr = data::read_lr_rest(a.lr);
  const auto hr = data::read_hr_rest(a.hr);
  const auto t0 = std::chrono::steady_clock::now();
  const auto nb = data::compute_network_neighborhoods(exec::omp, lr, hr, a.k, a.lr_k > 0 ? a.lr_k : a.k);
  const auto t1 = std::chrono::steady_clock::now();
  data::save_network_neighborhoods(a.out, nb);
  nlohmann::ordered_json j;
  j["lr_vertices"] = lr.V.rows();
  j["hr_vertices"] = hr.V.rows();
  j["k"] = a.k;
  j["assignment_cost"] = nb.upsampling.assignment_cost;
  j["assignment_globally_optimal"] = nb.upsampling.assignment_globally_optimal;
  j["seconds"] = std::chrono::duration<double>(t1 - t0).count();
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
