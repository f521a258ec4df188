#pragma once
// Fixtures of the interpolator tests: brute-force stand-in neighbourhoods, and the bunny example: rest shapes, the authors' precomputed
// surface-to-tet geodesic neighbourhoods (first 20 of 100 columns) with their LR→HR mapping, and
// the displacements of a few training frames.
#include <simsr/interp/problem.hpp>
#include <simsr/io/npy.hpp>
#include <simsr/io/npz.hpp>
#include <simsr/io/obj.hpp>

#include <algorithm>
#include <filesystem>
#include <utility>
#include <vector>

namespace simsr::test {

using interp::UpsamplingProblem;

/// Stand-in neighbourhoods: the k Euclidean-nearest LR vertices (L) of each HR vertex (H), by brute
/// force (sorted by distance, then id), as the interpolators only read ids and distances.
inline neighbors::UpsamplingNeighborhoods brute_neighborhoods(const Points<>& L, const Points<>& H, Index k) {
  neighbors::UpsamplingNeighborhoods nb;
  nb.indices.resize(H.rows(), k);
  nb.distances.resize(H.rows(), k);
  for (Index j = 0; j < H.rows(); ++j) {
    std::vector<std::pair<double, Index>> d;
    for (Index i = 0; i < L.rows(); ++i) d.emplace_back((L.row(i) - H.row(j)).norm(), i);
    std::partial_sort(d.begin(), d.begin() + k, d.end());
    for (Index n = 0; n < k; ++n) nb.indices(j, n) = VIndex(d[n].second), nb.distances(j, n) = d[n].first;
  }
  return nb;
}

/// Displacements from the rest shapes of the frames asked for.
struct Bunny {
  UpsamplingProblem<> problem;
  std::vector<Points<>> lr_frames, hr_frames;
};

/// Fills `b`; false when the data are absent.
inline bool load_bunny(Bunny& b, std::vector<Index> frames) {
#ifdef SIMSR_DATA_DIR
  const std::filesystem::path dir = std::filesystem::path(SIMSR_DATA_DIR) / "bunny";
  if (!std::filesystem::exists(dir / "train_frames.npz")) return false;
  b.problem.lr = io::read_obj_tets(dir / "lrestshape.obj");
  b.problem.hr = io::read_obj_triangles(dir / "hrestshape.obj");
  neighbors::UpsamplingNeighborhoods nb;
  nb.indices = io::read_npy(dir / "geo_dist_surf2tet_idx.npy").to_matrix<VIndex>().leftCols(20);
  nb.distances = io::read_npy(dir / "geo_dist_surf2tet.npy").to_matrix<double>().leftCols(20);
  // the authors' LR→HR mapping: the HR vertex at distance 0 of each LR vertex
  nb.lr_to_hr = IndexVector::Constant(b.problem.num_lr(), -1);
  for (Index j = 0; j < nb.indices.rows(); ++j)
    if (nb.distances(j, 0) == 0.0) nb.lr_to_hr[nb.indices(j, 0)] = VIndex(j);
  if ((nb.lr_to_hr.array() < 0).any()) return false;
  b.problem.neighborhoods = std::move(nb);
  io::NpzReader z(dir / "train_frames.npz");
  const auto lo = z.read("lowres").to_vector<double>(), hi = z.read("highres").to_vector<double>();
  const Index n = b.problem.num_lr(), m = b.problem.num_hr();
  for (Index f : frames) {
    b.lr_frames.push_back(Eigen::Map<const Points<>>(lo.data() + f * n * 3, n, 3) - b.problem.lr.V);
    b.hr_frames.push_back(Eigen::Map<const Points<>>(hi.data() + f * m * 3, m, 3) - b.problem.hr.V);
  }
  return true;
#else
  (void)b, (void)frames;
  return false;
#endif
}


}  // namespace simsr::test
