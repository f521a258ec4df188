#pragma once
/// \file
/// The synthetic paper-size network of bench_nn and bench_cuda (scripts/peers/nn_bench_peer.py
/// builds the same one in numpy): LR = a 32×31×16 lattice of spacing h = 0.03, centred at 0, with
/// the deterministic jitter 0.2·h·sin(1.7·i + 2.3·c + 0.5·c²) (i = vertex id, c = coordinate);
/// HR = a Fibonacci sphere of 35,637 points scaled onto the ellipsoid of semi-axes
/// √3·1.05·(half extents of the lattice), around the LR points; LR graph = the knn nearest LR
/// vertices (self first), up_indices = the 20 nearest LR vertices of each HR vertex with their
/// Euclidean distances (neighbors::KdTree). The LR displacements are N(0, 0.3²) per coordinate
/// (normalized units), seeded.

#include <simsr/neighbors/kd_tree.hpp>
#include <simsr/nn/super_resolution_net.hpp>

#include <cmath>
#include <numbers>
#include <random>

namespace simsr::bench {

using nn::Matrix;

inline constexpr Index kLr = 15872, kHr = 35637, kUpK = 20;


/// The synthetic geometry of the file comment (knn columns of LR graph, upK HR→LR neighbours).
inline nn::NetworkGeometry paper_geometry(Index knn, Index up_k) {
  nn::NetworkGeometry g;
  const int nx = 32, ny = 31, nz = 16;
  const double h = 0.03;
  g.lr_rest.resize(kLr, 3);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const Index v = i + nx * (j + ny * k);
        const double p[3] = {(i - 0.5 * (nx - 1)) * h, (j - 0.5 * (ny - 1)) * h, (k - 0.5 * (nz - 1)) * h};
        for (int c = 0; c < 3; ++c) g.lr_rest(v, c) = p[c] + 0.2 * h * std::sin(1.7 * double(v) + 2.3 * c + 0.5 * c * c);
      }
  const double s = std::sqrt(3.0) * 1.05;
  const double axes[3] = {s * 0.5 * (nx - 1) * h, s * 0.5 * (ny - 1) * h, s * 0.5 * (nz - 1) * h};
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  g.hr_rest.resize(kHr, 3);
  for (Index j = 0; j < kHr; ++j) {
    const double z = 1.0 - (2.0 * double(j) + 1.0) / double(kHr), r = std::sqrt(1.0 - z * z), phi = golden * double(j);
    g.hr_rest.row(j) << axes[0] * r * std::cos(phi), axes[1] * r * std::sin(phi), axes[2] * z;
  }
  neighbors::KdTree<double> tree(g.lr_rest);
  const auto lr = tree.query(exec::omp, g.lr_rest, knn);
  g.lr_graph = lr.indices;
  const auto up = tree.query(exec::omp, g.hr_rest, up_k);
  g.up_indices = up.indices;
  g.up_distances = up.distances;
  return g;
}

inline nn::NetworkConfig paper_config() {
  auto cfg = nn::NetworkConfig::official();
  cfg.up_k = kUpK;
  return cfg;
}

inline const nn::NetworkGeometry& paper_geo() {
  static const nn::NetworkGeometry g = paper_geometry(paper_config().knn, kUpK);
  return g;
}

inline Matrix<float> paper_ldx(Index B) {
  std::mt19937_64 rng(7);
  std::normal_distribution<float> n(0.0f, 0.3f);
  Matrix<float> x(B * kLr, 3);
  for (Index i = 0; i < x.size(); ++i) x.data()[i] = n(rng);
  return x;
}

}  // namespace simsr::bench
