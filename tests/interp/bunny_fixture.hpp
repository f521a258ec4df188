#pragma once
// The bunny example for the interpolator tests: rest shapes, the authors' precomputed
// surface-to-tet geodesic neighbourhoods (first 20 of 100 columns) with their LR→HR mapping, and
// the displacements of a few training frames.
#include <simsr/interp/problem.hpp>
#include <simsr/io/npy.hpp>
#include <simsr/io/npz.hpp>
#include <simsr/io/obj.hpp>

#include <filesystem>
#include <vector>

namespace simsr::test {

using interp::UpsamplingProblem;

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
