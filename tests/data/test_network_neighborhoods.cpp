#include <simsr/data/network_neighborhoods.hpp>
#include <simsr/data/rest_shapes.hpp>
#include <simsr/mesh/generators.hpp>

#include <doctest/doctest.h>

#include "../support/error_of.hpp"

#include <filesystem>
#include <string>

using namespace simsr;
using simsr::test::error_of;

TEST_CASE("network neighbourhoods: the authors' bunny files and rest shapes") {
  const auto dir = std::filesystem::path(SIMSR_DATA_DIR) / "bunny";
  REQUIRE_MESSAGE(std::filesystem::exists(dir / "geo_dist_surf2tet_idx.npy"), "the bundled data is missing: ", dir.string());
  const auto lr = data::read_lr_rest(dir / "lrestshape.obj");
  const auto hr = data::read_hr_rest(dir / "hrestshape.obj");
  CHECK(lr.num_vertices() == 1747);
  CHECK(hr.num_vertices() == 2503);
  const auto nb = data::read_official_neighborhoods(dir, lr.num_vertices(), hr.num_vertices());
  CHECK(nb.upsampling.indices.rows() == 2503);
  CHECK(nb.lr_graph.rows() == 1747);
  for (Index i = 0; i < nb.lr_graph.rows(); ++i) CHECK(nb.lr_graph(i, 0) == i);  // self first
  CHECK(error_of([&] { data::read_official_neighborhoods(dir, 1746, 2503); }).find("geo_dist_tet2tet_idx.npy") != std::string::npos);
  CHECK(error_of([&] { data::read_official_neighborhoods(dir, 1747, 2504); }).find("geo_dist_surf2tet_idx.npy") != std::string::npos);
  const std::string e = error_of([&] { data::read_lr_rest(dir / "hrestshape.obj"); });
  INFO(e);
  CHECK(e.find("hrestshape.obj") != std::string::npos);  // a surface is not an LR volume
}

TEST_CASE("network neighbourhoods: computed, saved and read back; a wrong index is named") {
  const TetMesh<> lr = box_tet_mesh<double>(3, 3, 3, Vec3<>(-1, -1, -1), Vec3<>(1, 1, 1));
  TriMesh<> hr = icosphere<double>(2, 0.9);  // 162 vertices inside the 64-vertex box
  const auto nb = data::compute_network_neighborhoods(exec::omp, lr, hr, 6, 4);
  const auto seq = data::compute_network_neighborhoods(exec::seq, lr, hr, 6, 4);
  CHECK(nb.upsampling.indices == seq.upsampling.indices);
  CHECK(nb.lr_graph == seq.lr_graph);
  const auto file = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "data_neighbors.npz";
  data::save_network_neighborhoods(file, nb);
  const auto back = data::read_network_neighborhoods(file, lr.num_vertices(), hr.num_vertices());
  CHECK(back.upsampling.indices == nb.upsampling.indices);
  CHECK(back.upsampling.distances == nb.upsampling.distances);
  CHECK(back.lr_graph == nb.lr_graph);
  CHECK(error_of([&] { data::read_network_neighborhoods(file, lr.num_vertices() + 1, hr.num_vertices()); }).find("lr_to_hr") != std::string::npos);
  auto bad = nb;
  bad.lr_graph(2, 1) = VIndex(lr.num_vertices());
  data::save_network_neighborhoods(file, bad);
  const std::string e = error_of([&] { data::read_network_neighborhoods(file, lr.num_vertices(), hr.num_vertices()); });
  INFO(e);
  CHECK(e.find("LR graph (N×k): entry (2, 1)") != std::string::npos);
  CHECK(!error_of([&] { data::compute_network_neighborhoods(exec::seq, lr, hr, 0, 4); }).empty());
}
