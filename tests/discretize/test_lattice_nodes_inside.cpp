#include <doctest/doctest.h>

#include <simsr/discretize/bcc_lattice.hpp>
#include <simsr/mesh/generators.hpp>

#include <random>

using namespace simsr;

TEST_CASE("lattice_nodes_inside agrees with the per-point winding test on every node of random lattices") {
  std::mt19937 rng(51);
  std::uniform_real_distribution<double> u(0.8, 1.2);
  for (int trial = 0; trial < 8; ++trial) {
    TriMesh<> s = icosphere<double>(2, 1.0);
    for (Index v = 0; v < s.V.rows(); ++v) s.V.row(v) = s.V.row(v).cwiseProduct(Eigen::RowVector3d(u(rng), u(rng), u(rng)));
    const double h = 0.12 + 0.05 * double(trial);
    const auto lattice = discretize::bcc_lattice(s, h);
    const auto fast = discretize::lattice_nodes_inside(lattice, s);
    const auto slow = discretize::inside_surface(s, lattice.mesh.V);
    REQUIRE(fast.size() == slow.size());
    Index inside = 0, differ = 0;
    for (std::size_t v = 0; v < fast.size(); ++v) {
      inside += fast[v];
      differ += fast[v] != slow[v];
    }
    CAPTURE(h);
    CHECK(differ == 0);
    CHECK(inside > 0);
    CHECK(inside < lattice.mesh.V.rows());  // cells reach past the surface: some nodes are outside
  }
}
