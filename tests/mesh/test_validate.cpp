#include <doctest/doctest.h>

#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/validate.hpp>

#include <limits>

#include "fixtures.hpp"

namespace mesh_test_validate {

using namespace simsr;
using namespace simsr::test;

namespace {

/// Runs validate and returns (kind, element) of the MeshError, or ("", −2) when nothing is thrown.
template <class Mesh>
std::pair<std::string, Index> error_of(const Mesh& m, const ValidateOptions& opt = {}) {
  try {
    validate(exec::seq, m, opt);
  } catch (const MeshError& e) {
    return {e.kind(), e.element()};
  }
  return {"", -2};
}

/// Four coplanar vertices of the box grid: corners of the bottom face of the first cube.
std::array<VIndex, 4> coplanar_quad(int nx) { return {0, 1, VIndex(nx + 1), VIndex(nx + 2)}; }

}  // namespace

TEST_CASE("validate accepts box tetrahedralizations and their boundary surfaces") {
  std::mt19937 rng(60);
  for (int trial = 0; trial < 10; ++trial) {
    TetMesh<> m = box_tets(1 + trial % 4, 2, 1 + trial % 3, 0.01 + trial, Vec3<>::Zero(), trial % 2);
    jitter(m.V, 0.05 * (0.01 + trial), rng);
    CHECK_NOTHROW(validate(exec::seq, m));
    CHECK_NOTHROW(validate(exec::omp, m));
    CHECK(check(exec::seq, m).ok());
    CHECK(check(exec::seq, m).summary().empty());
    CHECK_NOTHROW(validate(exec::seq, boundary_surface(m)));
  }
}

TEST_CASE("validate names the offending tet for each kind of problem, at random positions") {
  std::mt19937 rng(61);
  const int nx = 4;
  const TetMesh<> good = box_tets(nx, 3, 3, 0.5);
  std::uniform_int_distribution<Index> pick_tet(0, good.T.rows() - 1);
  std::uniform_int_distribution<Index> pick_vertex(0, good.V.rows() - 1);
  for (int trial = 0; trial < 40; ++trial) {
    const Index t = pick_tet(rng);
    CAPTURE(t);
    {  // out of range
      TetMesh<> m = good;
      m.T(t, rng() % 4) = (rng() & 1) ? VIndex(m.V.rows() + rng() % 5) : VIndex(-1 - VIndex(rng() % 5));
      CHECK(error_of(m) == std::pair<std::string, Index>{"tet", t});
      CHECK(check(exec::seq, m).out_of_range.count == 1);
      CHECK(check(exec::seq, m).out_of_range.first == t);
    }
    {  // repeated vertex
      TetMesh<> m = good;
      const int a = int(rng() % 4), b = (a + 1 + int(rng() % 3)) % 4;
      m.T(t, a) = m.T(t, b);
      CHECK(error_of(m) == std::pair<std::string, Index>{"tet", t});
      CHECK(check(exec::seq, m).repeated_vertex.first == t);
    }
    {  // degenerate: four coplanar vertices
      TetMesh<> m = good;
      const auto q = coplanar_quad(nx);
      m.T.row(t) << q[0], q[1], q[2], q[3];
      CHECK(error_of(m) == std::pair<std::string, Index>{"tet", t});
      CHECK(check(exec::seq, m).degenerate.count == 1);
      CHECK(check(exec::seq, m).degenerate.first == t);
    }
    {  // inverted: an odd permutation of the corners
      TetMesh<> m = good;
      std::swap(m.T(t, 0), m.T(t, 1 + rng() % 3));
      CHECK(error_of(m) == std::pair<std::string, Index>{"tet", t});
      CHECK(check(exec::seq, m).inverted.first == t);
      ValidateOptions allow;
      allow.allow_inverted = true;
      CHECK(error_of(m, allow).second == -2);
    }
    {  // non-finite coordinate: reported as the vertex, before any tet problem
      TetMesh<> m = good;
      const Index v = pick_vertex(rng);
      m.V(v, rng() % 3) = (rng() & 1) ? std::numeric_limits<double>::quiet_NaN() : std::numeric_limits<double>::infinity();
      std::swap(m.T(t, 0), m.T(t, 1));
      CHECK(error_of(m) == std::pair<std::string, Index>{"vertex", v});
      CHECK(check(exec::seq, m).non_finite_vertex.first == v);
    }
  }
}

TEST_CASE("check counts several problems, classifies each tet once, and names the first of each kind") {
  std::mt19937 rng(62);
  for (int trial = 0; trial < 20; ++trial) {
    TetMesh<> m = box_tets(5, 4, 3);
    std::vector<Index> order(static_cast<std::size_t>(m.T.rows()));
    std::iota(order.begin(), order.end(), Index(0));
    std::shuffle(order.begin(), order.end(), rng);
    const int n_inv = 1 + int(rng() % 6), n_oor = 1 + int(rng() % 6);
    std::vector<Index> inv(order.begin(), order.begin() + n_inv), oor(order.begin() + n_inv, order.begin() + n_inv + n_oor);
    for (Index t : inv) std::swap(m.T(t, 2), m.T(t, 3));
    for (Index t : oor) m.T(t, 0) = VIndex(m.V.rows());
    m.T(inv[0], 1) = VIndex(m.V.rows() + 7);  // inverted and out of range: counted as out of range only
    const MeshReport r = check(exec::omp, m);
    CHECK(r.inverted.count == n_inv - 1);
    CHECK(r.out_of_range.count == n_oor + 1);
    CHECK(r.out_of_range.first == std::min(*std::min_element(oor.begin(), oor.end()), inv[0]));
    if (n_inv > 1) CHECK(r.inverted.first == *std::min_element(inv.begin() + 1, inv.end()));
    CHECK_FALSE(r.ok());
    const MeshReport s = check(exec::seq, m);
    CHECK(s.inverted.count == r.inverted.count);
    CHECK(s.out_of_range.first == r.out_of_range.first);
    Index first_bad = std::min(*std::min_element(inv.begin(), inv.end()), *std::min_element(oor.begin(), oor.end()));
    CHECK(error_of(m).second == first_bad);
  }
}

TEST_CASE("validate: degenerate tolerance is relative to the longest edge (scale-invariant)") {
  for (double scale : {1e-6, 1.0, 1e6}) {
    TetMesh<> m;
    m.V.resize(4, 3);
    m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.3, 0.3, 1e-9;  // volume/ℓ³ ≈ 1.7e-10
    m.V *= scale;
    m.T.resize(1, 4);
    m.T << 0, 1, 2, 3;
    ValidateOptions loose, tight, off;
    loose.degenerate_tolerance = 1e-9;
    tight.degenerate_tolerance = 1e-11;
    off.degenerate_tolerance = -1;
    CHECK(error_of(m, loose) == std::pair<std::string, Index>{"tet", 0});
    CHECK(error_of(m, tight).second == -2);
    m.V(3, 2) = 0;  // exactly flat
    CHECK(error_of(m, off).second == -2);
    CHECK(check(exec::seq, m, off).degenerate.count == 0);
    CHECK(check(exec::seq, m).degenerate.count == 1);
  }
}

TEST_CASE("validate triangle meshes; unreferenced vertices are reported, not errors") {
  std::mt19937 rng(63);
  TriMesh<> s = icosphere(2);
  CHECK_NOTHROW(validate(exec::seq, s));
  s.V.conservativeResize(s.V.rows() + 2, 3);
  s.V.bottomRows(2).setConstant(5.0);
  CHECK_NOTHROW(validate(exec::seq, s));
  CHECK(check(exec::seq, s).unreferenced_vertex.count == 2);
  CHECK(check(exec::seq, s).unreferenced_vertex.first == s.V.rows() - 2);
  for (int trial = 0; trial < 20; ++trial) {
    const Index f = Index(rng() % s.F.rows());
    TriMesh<> m = s;
    switch (trial % 3) {
      case 0: m.F(f, rng() % 3) = VIndex(m.V.rows()); break;
      case 1: m.F(f, 1) = m.F(f, 0); break;
      case 2: m.V.row(m.F(f, 2)) = (m.V.row(m.F(f, 0)) + m.V.row(m.F(f, 1))) / 2; break;  // flat
    }
    if (trial % 3 == 2) {  // moving a shared vertex onto an edge may also flatten an earlier triangle
      const MeshReport r = check(exec::seq, m);
      CHECK(r.degenerate.count >= 1);
      CHECK(error_of(m) == std::pair<std::string, Index>{"triangle", r.degenerate.first});
      CHECK(r.degenerate.first <= f);
    } else {
      CHECK(error_of(m) == std::pair<std::string, Index>{"triangle", f});
    }
  }
  TriMesh<> m = s;
  m.V(3, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK(error_of(m) == std::pair<std::string, Index>{"vertex", 3});
  try {
    validate(exec::seq, m);
  } catch (const MeshError& e) {
    CHECK(std::string(e.what()).find("vertex 3") == 0);
  }
}

}  // namespace mesh_test_validate
