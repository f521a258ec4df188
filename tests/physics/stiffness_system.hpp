#pragma once
// Test fixture shared by the linear-solver tests: a real SPD stiffness system.

#include <simsr/mesh/generators.hpp>
#include <simsr/physics/elastic_energy.hpp>
#include <simsr/physics/hessian.hpp>

#include <random>
#include <vector>

#include "stvk_material.hpp"

namespace simsr_test {

/// The stiffness matrix (StVK at rest, λ = 1, μ = 2) of an nx×ny×ny-cell beam of length nx/ny
/// and unit cross-section, its x = 0 end fixed (identity rows), and a random load on the free DOFs.
struct StiffnessSystem {
  simsr::TetMesh<double> mesh;
  simsr::physics::BlockHessian<> H;
  std::vector<char> fixed;
  simsr::VecX<> b;
  const simsr::physics::SparseMatrix<>& A() { return H.assemble(simsr::exec::seq, fixed); }
};

inline StiffnessSystem stiffness_system(simsr::Index nx, simsr::Index ny, unsigned seed) {
  using namespace simsr;
  StiffnessSystem s{box_tet_mesh<double>(nx, ny, ny, Vec3<>(0, 0, 0), Vec3<>(double(nx) / double(ny), 1, 1)), {}, {}, {}};
  physics::ElasticEnergy<StVK> E(s.mesh, {1.0, 2.0});
  s.H = physics::BlockHessian<>(s.mesh.num_vertices(), s.mesh.T);
  s.H.set_zero();
  E.add_hessian(exec::seq, s.mesh.V, s.H, physics::Definiteness::project);
  s.fixed.assign(std::size_t(3 * s.mesh.num_vertices()), 0);
  for (Index v = 0; v < s.mesh.num_vertices(); ++v)
    if (s.mesh.V(v, 0) == 0.0)
      for (int c = 0; c < 3; ++c) s.fixed[std::size_t(3 * v + c)] = 1;
  std::mt19937 rng(seed);
  std::normal_distribution<double> N;
  s.b.resize(3 * s.mesh.num_vertices());
  for (Index i = 0; i < s.b.size(); ++i) s.b[i] = s.fixed[std::size_t(i)] ? 0.0 : N(rng);
  return s;
}

}  // namespace simsr_test
