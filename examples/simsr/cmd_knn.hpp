#pragma once
// `simsr knn --points P.npy --queries Q.npy --k K --out OUT.npz`: Euclidean k nearest points
// (nanoflann KD-tree, exec::omp). OUT gets `indices` (Q×K int64) and `distances` (Q×K float64);
// stdout gets one JSON line {"build_ms":…, "query_ms":…}.
#include <simsr/io/npy.hpp>
#include <simsr/io/npz.hpp>
#include <simsr/neighbors/kd_tree.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <memory>
#include <string>

namespace simsr::cli {

/// An N×3 array file as points; ShapeError naming the file otherwise.
inline Points<double> read_points_npy(const std::string& file) {
  const io::NpyArray a = io::read_npy(file);
  if (a.ndim() != 2 || a.shape[1] != 3) throw ShapeError(file, {-1, 3}, a.shape);
  return a.to_points<double>();
}

struct KnnArgs {
  std::string points, queries, out;
  Index k = 0;
};

inline int knn(const KnnArgs& a) {
  using clock = std::chrono::steady_clock;
  const Points<double> P = read_points_npy(a.points), Q = read_points_npy(a.queries);
  const auto t0 = clock::now();
  neighbors::KdTree<double> tree(P);
  const auto t1 = clock::now();
  neighbors::KnnResult<double> r;
  tree.query_into(exec::omp, Q, a.k, r);
  const auto t2 = clock::now();
  io::NpzArrays z;
  z["indices"] = io::make_npy(r.indices.cast<std::int64_t>().eval());
  z["distances"] = io::make_npy(r.distances);
  io::write_npz(a.out, z);
  const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  nlohmann::ordered_json j;
  j["build_ms"] = ms(t1 - t0);
  j["query_ms"] = ms(t2 - t1);
  std::cout << j.dump() << '\n';
  return 0;
}

inline void add_knn(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("knn", "Euclidean k nearest neighbours of query points (KD-tree)");
  auto a = std::make_shared<KnnArgs>();
  cmd->add_option("--points", a->points, "N×3 .npy points to search")->required();
  cmd->add_option("--queries", a->queries, "Q×3 .npy query points")->required();
  cmd->add_option("--k", a->k, "neighbours per query (1..N)")->required();
  cmd->add_option("--out", a->out, "output .npz (indices Q×K int64, distances Q×K float64)")->required();
  cmd->callback([&action, a] { action = [a] { return knn(*a); }; });
}

}  // namespace simsr::cli
