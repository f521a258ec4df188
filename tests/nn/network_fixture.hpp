#pragma once
/// \file
/// Small random geometries and shrunken configs for the network tests: random LR/HR point sets,
/// an LR kNN graph with self first, HR→LR Euclidean neighbours with their distances, and a random
/// row-stochastic M×N "embedding" (4 entries per row) for the residual option.

#include <simsr/nn/super_resolution_net.hpp>

#include <algorithm>
#include <numeric>
#include <random>

namespace simsr::test {

/// The k nearest of `pts` to q (brute force, ties by index), nearest first.
inline std::vector<Index> nearest(const Points<double>& pts, const Vec3<double>& q, Index k) {
  std::vector<Index> order(std::size_t(pts.rows()));
  std::iota(order.begin(), order.end(), Index(0));
  std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) {
    return (pts.row(a).transpose() - q).squaredNorm() < (pts.row(b).transpose() - q).squaredNorm();
  });
  order.resize(std::size_t(k));
  return order;
}

inline nn::NetworkGeometry small_network_geometry(std::mt19937_64& rng, Index N, Index M, const nn::NetworkConfig& cfg) {
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  nn::NetworkGeometry g;
  g.lr_rest.resize(N, 3);
  g.hr_rest.resize(M, 3);
  for (Index i = 0; i < g.lr_rest.size(); ++i) g.lr_rest.data()[i] = u(rng);
  for (Index i = 0; i < g.hr_rest.size(); ++i) g.hr_rest.data()[i] = u(rng);
  const Index kg = std::min<Index>(N, cfg.knn + 2), ku = std::min<Index>(N, cfg.up_k + 1);
  g.lr_graph.resize(N, kg);
  for (Index i = 0; i < N; ++i) {
    const auto nb = nearest(g.lr_rest, g.lr_rest.row(i).transpose(), kg);
    for (Index j = 0; j < kg; ++j) g.lr_graph(i, j) = VIndex(nb[std::size_t(j)]);
  }
  g.up_indices.resize(M, ku);
  g.up_distances.resize(M, ku);
  for (Index j = 0; j < M; ++j) {
    const auto nb = nearest(g.lr_rest, g.hr_rest.row(j).transpose(), ku);
    for (Index i = 0; i < ku; ++i) {
      g.up_indices(j, i) = VIndex(nb[std::size_t(i)]);
      g.up_distances(j, i) = (g.lr_rest.row(nb[std::size_t(i)]) - g.hr_rest.row(j)).norm();
    }
  }
  std::vector<Eigen::Triplet<double>> t;
  std::uniform_int_distribution<Index> pick(0, N - 1);
  for (Index j = 0; j < M; ++j) {
    double w[4], s = 0;
    for (double& x : w) s += (x = 0.1 + u(rng) + 0.1);
    for (int c = 0; c < 4; ++c) t.emplace_back(j, pick(rng), w[c] / s);
  }
  g.embedding.resize(M, N);
  g.embedding.setFromTriplets(t.begin(), t.end());
  return g;
}

/// `base` with every width shrunk (FD-checkable in double in well under a second).
inline nn::NetworkConfig tiny_config(nn::NetworkConfig c) {
  c.pos_feat_dim = 4;
  c.emb_feat_dims = {7, 5, 6};
  c.knn = 3;
  c.up_k = 4;
  c.up_hidden = c.up_batch_norm ? std::vector<Index>{6, 5} : std::vector<Index>{6};
  c.decoder_dims = c.decoder_dead_layer ? std::vector<Index>{18, 9, 6, 4, 3} : std::vector<Index>{18, 8, 5, 3};
  c.validate();
  return c;
}

}  // namespace simsr::test
