#pragma once
// The pipeline suites' data set in the bunny's layout (an LR box, an HR sphere inside it, frames
// of a 6-parameter smooth motion): DIR/bunny/{lrestshape.obj, hrestshape.obj, train_frames.npz}.
#include <simsr/data/paired_frames.hpp>
#include <simsr/pipeline/demo.hpp>
#include <simsr/io/obj.hpp>
#include <simsr/mesh/generators.hpp>

#include <filesystem>
#include <random>
#include <string>

namespace simsr::test {

/// SIMSR_TEST_TMP_DIR/<folder>/<name>, emptied, holding F frames (ids 100 + f) in the bunny's layout.
inline std::filesystem::path small_bunny_layout(const std::string& folder, const std::string& name, Index frames) {
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / folder / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "bunny");
  const auto lr = box_tet_mesh<double>(3, 3, 3, Vec3<>(-0.1, -0.1, -0.1), Vec3<>(0.1, 0.1, 0.1));
  const auto hr = icosphere<double>(2, 0.08);
  io::write_obj_tets(dir / "bunny" / "lrestshape.obj", lr);
  io::write_obj(dir / "bunny" / "hrestshape.obj", hr);
  const Index n = lr.V.rows(), m = hr.V.rows();
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, 0.01);
  data::PairedFrames<> p;
  p.lowres.resize(frames, 3 * n);
  p.highres.resize(frames, 3 * m);
  p.controls.resize(frames, 0);
  for (Index f = 0; f < frames; ++f) {
    const Eigen::RowVector3d a(g(rng), g(rng), g(rng)), b(g(rng), g(rng), g(rng));
    for (Index v = 0; v < n; ++v) p.lr(f).row(v) = lr.V.row(v) + a + b * (lr.V(v, 0) * 10) * (lr.V(v, 1) * 10);
    for (Index v = 0; v < m; ++v) p.hr(f).row(v) = hr.V.row(v) + a + b * (hr.V(v, 0) * 10) * (hr.V(v, 1) * 10);
    p.ids.push_back(100 + f);
  }
  data::write_paired_frames(dir / "bunny" / "train_frames.npz", p);
  return dir;
}

/// Demo options over such a folder: the bunny layout, DIR/out, k = 10, batches of 4, no progress
/// lines, network seed `seed`; each suite adds its methods and epochs.
inline pipeline::DemoOptions small_demo_options(const std::filesystem::path& dir, std::uint64_t seed) {
  pipeline::DemoOptions o;
  o.dataset = "bunny";
  o.data = dir;
  o.out = dir / "out";
  o.method_parameters.k = 10;
  o.recipe.batch_size = 4;
  o.recipe.seed = seed;
  o.progress = false;
  return o;
}

}  // namespace simsr::test
