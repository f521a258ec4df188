// The force terms inside Newton solves: contact that grows the Hessian pattern, an obstacle
// pushed into a block, track and point springs with a hinged jaw.
#include <simsr/discretize/embedding.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/physics/elastic_energy.hpp>
#include <simsr/physics/forces/forces.hpp>
#include <simsr/physics/materials/neo_hookean.hpp>
#include <simsr/physics/quasistatic.hpp>

#include <doctest/doctest.h>

#include <numbers>

using namespace simsr;
using namespace simsr::physics;

namespace {

/// Two meshes in one (vertex indices of `b` shifted by a's vertex count).
TetMesh<> combine(const TetMesh<>& a, const TetMesh<>& b) {
  TetMesh<> m;
  m.V.resize(a.V.rows() + b.V.rows(), 3);
  m.V << a.V, b.V;
  m.T.resize(a.T.rows() + b.T.rows(), 4);
  m.T << a.T, (b.T.array() + VIndex(a.V.rows())).matrix();
  return m;
}

/// Boundary triangles of `mesh` whose three corners satisfy pred (on rest positions).
template <class Pred>
Tris faces_where(const TetMesh<>& mesh, Pred pred) {
  const Tris F = boundary_faces(mesh.T);
  std::vector<Eigen::Matrix<VIndex, 1, 3>> keep;
  for (Index f = 0; f < F.rows(); ++f)
    if (pred(Vec3<>(mesh.V.row(F(f, 0)))) && pred(Vec3<>(mesh.V.row(F(f, 1)))) && pred(Vec3<>(mesh.V.row(F(f, 2))))) keep.push_back(F.row(f));
  Tris out(Index(keep.size()), 3);
  for (std::size_t k = 0; k < keep.size(); ++k) out.row(Index(k)) = keep[k];
  return out;
}

}  // namespace

TEST_CASE("self-contact in Newton: a block pressed onto another stops on it; the Hessian pattern grows for the new pairs") {
  const auto lower = box_tet_mesh<double>(4, 4, 2, Vec3<>(0, 0, 0), Vec3<>(1, 1, 0.5));
  const auto upper = box_tet_mesh<double>(2, 2, 2, Vec3<>(0.25, 0.25, 0.51), Vec3<>(0.75, 0.75, 0.81));
  const auto mesh = combine(lower, upper);
  const Index n = mesh.num_vertices();
  ElasticEnergy<NeoHookean<>> elastic(mesh, NeoHookean<>::from_young_poisson(1e5, 0.3));
  // Upper block's bottom vertices against the lower block's top triangles.
  const IndexVector contact_vertices = select_vertices(mesh.V, [](const Vec3<>& p) { return std::abs(p.z() - 0.51) < 1e-12; });
  const Tris contact_triangles = faces_where(mesh, [](const Vec3<>& p) { return std::abs(p.z() - 0.5) < 1e-12; });
  REQUIRE(contact_vertices.size() == 9);
  REQUIRE(contact_triangles.rows() == 2 * 16);
  SelfContact<> contact(contact_vertices, contact_triangles, n, 1e6, 0.02);
  // Floor holds the lower block; the upper block's top face is pushed 5 cm down (gap 1 cm).
  BoneAttachments<> bones(mesh.V);
  bones.add_bone("floor", select_vertices(mesh.V, [](const Vec3<>& p) { return p.z() < 1e-12; }));
  bones.add_bone("press", select_vertices(mesh.V, [](const Vec3<>& p) { return p.z() > 0.81 - 1e-12; }));
  bones.set_transform("press", RigidTransform<>{Mat3<>::Identity(), Vec3<>(0, 0, -0.05)});

  QuasistaticSolver<SparseCholesky<>> newton(n, mesh.T);
  const auto version = newton.hessian().pattern_version();
  Points<> x = mesh.V;
  const auto report = newton.solve(exec::seq, x, bones.boundary(), elastic, contact);
  CHECK(report.converged);
  CHECK(newton.hessian().pattern_version() != version);  // contact pairs across the two meshes
  // Every pressed vertex rests on the (deformed) lower surface: above its closest point, within d̂.
  const auto pairs = contact.pairs(x);
  std::vector<char> touching(std::size_t(n), 0);
  for (const auto& c : pairs) {
    Vec3<> q = Vec3<>::Zero();
    for (int i = 0; i < 3; ++i) q += c.barycentric[i] * Vec3<>(x.row(contact_triangles(c.triangle, i)));
    CHECK(x(c.vertex, 2) > q.z());
    CHECK(c.distance < 0.02);
    touching[std::size_t(c.vertex)] = 1;
  }
  for (Index k = 0; k < contact_vertices.size(); ++k) CHECK(touching[std::size_t(contact_vertices[k])]);
  const double lowest = x(contact_vertices[0], 2);
  // The lower block is squeezed where the upper one rests: its top centre moved down.
  const Index centre = select_vertices(mesh.V, [](const Vec3<>& p) { return (p - Vec3<>(0.5, 0.5, 0.5)).norm() < 1e-12; })[0];
  CHECK(x(centre, 2) < 0.5 - 1e-3);
  // Without contact the upper block passes through the lower one.
  Points<> y = mesh.V;
  QuasistaticSolver<SparseCholesky<>> free_fall(n, mesh.T);
  free_fall.solve(exec::seq, y, bones.boundary(), elastic);
  CHECK(y(contact_vertices[0], 2) < 0.47);
  CHECK(lowest > y(contact_vertices[0], 2) + 0.02);
}

TEST_CASE("obstacle contact in Newton: a rigid sphere pushed into a block dents it and the surface stays outside") {
  const auto mesh = box_tet_mesh<double>(6, 6, 3, Vec3<>(0, 0, 0), Vec3<>(1, 1, 0.5));
  ElasticEnergy<NeoHookean<>> elastic(mesh, NeoHookean<>::from_young_poisson(1e5, 0.3));
  const IndexVector top = select_vertices(mesh.V, [](const Vec3<>& p) { return p.z() > 0.5 - 1e-12; });
  const double radius = 0.3;
  ObstacleContact contact(Sphere<>(Vec3<>(0.5, 0.5, 0.5 + radius), radius), top, mesh.num_vertices(), 1e7);
  BoneAttachments<> floor(mesh.V);
  floor.add_bone("floor", select_vertices(mesh.V, [](const Vec3<>& p) { return p.z() < 1e-12; }));
  QuasistaticSolver<SparseCholesky<>> newton(mesh.num_vertices(), mesh.T);
  Points<> x = mesh.V;
  double previous_dent = 0;
  for (double push : {0.02, 0.05, 0.08}) {  // the sphere moves down frame by frame (warm starts)
    contact.obstacle().set_centre(Vec3<>(0.5, 0.5, 0.5 + radius - push));
    const auto report = newton.solve(exec::seq, x, floor.boundary(), elastic, contact);
    CHECK(report.converged);
    const Index middle = select_vertices(mesh.V, [](const Vec3<>& p) { return (p - Vec3<>(0.5, 0.5, 0.5)).norm() < 1e-12; })[0];
    const double dent = 0.5 - x(middle, 2);
    CHECK(dent > 0.8 * push);  // the stiff penalty lets little penetration through
    CHECK(dent > previous_dent);
    previous_dent = dent;
    for (Index k = 0; k < top.size(); ++k) CHECK(contact.obstacle().distance(Vec3<>(x.row(top[k]))) > -0.01 * push);
  }
}

TEST_CASE("track springs, a point spring on a 'lip corner' and a hinged jaw in one solve") {
  const auto mesh = box_tet_mesh<double>(4, 2, 2, Vec3<>(0, 0, 0), Vec3<>(0.08, 0.04, 0.04));
  const Index n = mesh.num_vertices();
  ElasticEnergy<NeoHookean<>> flesh(mesh, NeoHookean<>::from_young_poisson(2e4, 0.45));
  BoneAttachments<> bones(mesh.V);
  bones.add_bone("cranium", select_vertices(mesh.V, [](const Vec3<>& p) { return p.x() < 1e-12; }));
  const Index jaw = bones.add_bone("jaw", select_vertices(mesh.V, [](const Vec3<>& p) { return p.x() > 0.08 - 1e-12 && p.z() < 1e-12; }));
  const double angle = 10 * std::numbers::pi / 180;
  bones.set_transform(jaw, hinge_rotation(Vec3<>(0.08, 0, 0.04), Vec3<>(0, 1, 0), angle));
  // Track springs on the top surface, pulling it 5 mm up; a point spring pulling a top corner sideways.
  const TriMesh<> skin{mesh.V, faces_where(mesh, [](const Vec3<>& p) { return p.z() > 0.04 - 1e-12; })};
  const auto emb = embed(exec::seq, mesh, skin.V);
  auto tracks = track_springs(exec::seq, emb, mesh, skin, 1e6);
  Points<> targets = skin.V;
  targets.col(2).array() += 0.005;
  const IndexVector top = select_vertices(mesh.V, [](const Vec3<>& p) { return p.z() > 0.04 - 1e-12; });
  // Only the top vertices carry area in `skin` (the others are not in its triangles): their springs pull.
  tracks.set_targets(targets);
  Points<> corner(1, 3);
  corner << 0.08, 0.04, 0.04;
  auto lip = point_springs(exec::seq, mesh, corner, 200.0);
  Points<> lip_target = corner;
  lip_target(0, 1) += 0.01;
  lip.set_targets(lip_target);

  QuasistaticSolver<ConjugateGradient<BlockJacobi<>>> newton(n, mesh.T);
  Points<> x = mesh.V;
  const auto report = newton.solve(exec::omp, x, bones.boundary(), flesh, tracks, lip);
  CHECK(report.converged);
  // Bones: exactly where their transforms put them.
  const auto bc = bones.boundary();
  for (Index k = 0; k < bc.size(); ++k) CHECK((x.row(bc.vertices[k]) - bc.targets.row(k)).norm() < 1e-14);
  const Points<> jaw_rest = [&] {
    Points<> r(bones.vertices(jaw).size(), 3);
    for (Index k = 0; k < r.rows(); ++k) r.row(k) = mesh.V.row(bones.vertices(jaw)[k]);
    return r;
  }();
  const Points<> jaw_now = bones.transform(jaw).apply(jaw_rest);
  for (Index k = 0; k < jaw_rest.rows(); ++k) CHECK((x.row(bones.vertices(jaw)[k]) - jaw_now.row(k)).norm() < 1e-14);
  // Free top vertices follow the track springs upward; the lip corner moves toward its target.
  double rise = 0;
  Index counted = 0;
  for (Index k = 0; k < top.size(); ++k)
    if (bones.owner(top[k]) < 0) {
      rise += x(top[k], 2) - mesh.V(top[k], 2);
      ++counted;
    }
  CHECK(counted > 0);
  CHECK(rise / double(counted) > 0.001);
  CHECK(lip.points(x)(0, 1) > corner(0, 1) + 1e-4);
  // Equilibrium: removing the lip spring's pull changes the solution (it was doing work).
  Points<> y = mesh.V;
  newton.solve(exec::seq, y, bones.boundary(), flesh, tracks);
  CHECK(lip.points(x)(0, 1) > lip.points(y)(0, 1) + 1e-4);
}
