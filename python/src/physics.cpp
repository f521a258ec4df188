/// \file
/// simsr.ElasticBody: a tet mesh of one isotropic material (physics::with_material by name) under
/// gravity, held by named rigid bones (Dirichlet sets with a transform each, the jaw's hinge among
/// them) and pulled by vertex springs, solved quasistatically (physics::QuasistaticSolver: Newton
/// with a line search, the warm start given). The energy terms and the solver are the library's;
/// this file only keeps them together behind one Python object.
#include "common.hpp"

#include <memory>

#include <simsr/physics/elastic_energy.hpp>
#include <simsr/physics/forces/bone_attachment.hpp>
#include <simsr/physics/forces/gravity.hpp>
#include <simsr/physics/forces/vertex_targets.hpp>
#include <simsr/physics/linear_solvers/linear_solvers.hpp>
#include <simsr/physics/materials/by_name.hpp>
#include <simsr/physics/quasistatic.hpp>

namespace simsr::python {
namespace {

using namespace simsr::physics;
using Solver = QuasistaticSolver<SparseCholesky<Scalar>>;

/// The elastic term of one material behind a virtual solve (the material is chosen at run time).
struct ElasticTerm {
  virtual ~ElasticTerm() = default;
  virtual NewtonReport solve(const std::string& policy, Solver& solver, Points<>& x, const DirichletBoundary<>& bc, const Gravity<>& gravity,
                             const VertexTargets<>* springs) = 0;
  virtual double energy(const std::string& policy, const Points<>& x) = 0;
};

template <class M>
struct ElasticTermOf final : ElasticTerm {
  ElasticEnergy<M> elastic;
  ElasticTermOf(const TetMesh<>& mesh, const M& material) : elastic(mesh, material) {}
  NewtonReport solve(const std::string& policy, Solver& solver, Points<>& x, const DirichletBoundary<>& bc, const Gravity<>& gravity,
                     const VertexTargets<>* springs) override {
    return with_policy(policy, [&](auto p) {
      return springs ? solver.solve(p, x, bc, elastic, gravity, *springs) : solver.solve(p, x, bc, elastic, gravity);
    });
  }
  double energy(const std::string& policy, const Points<>& x) override {
    return with_policy(policy, [&](auto p) { return double(elastic.energy(p, x)); });
  }
};

struct Body {
  TetMesh<> mesh;
  std::string material;
  std::unique_ptr<ElasticTerm> elastic;
  std::unique_ptr<Gravity<>> gravity;
  std::unique_ptr<BoneAttachments<>> bones;
  std::unique_ptr<VertexTargets<>> springs;
  std::unique_ptr<Solver> solver;
  std::unique_ptr<std::mutex> mutex = std::make_unique<std::mutex>();
};

py::dict report_dict(const NewtonReport& r) {
  py::dict d;
  d["converged"] = r.converged;
  d["iterations"] = r.iterations;
  d["energy"] = r.energy;
  d["initial_gradient_norm"] = r.initial_gradient_norm;
  d["gradient_norm"] = r.gradient_norm;
  d["linear_iterations"] = r.linear_iterations;
  return d;
}

IndexVector vertex_list(const py::handle& h, const std::string& what) {
  py::array a = py::array::ensure(h);
  if (!a || a.ndim() != 1) throw ArgumentError(what + ": expected a 1-d integer array");
  return index_matrix<1>(a.reshape({a.size(), py::ssize_t(1)}), what);
}

}  // namespace

void bind_physics(py::module_& m) {
  m.def("material_names", &material_names, "The materials ElasticBody knows by name.");
  py::class_<Body>(m, "ElasticBody",
                   "A tet mesh of one hyperelastic material under gravity, held by rigid bones and pulled by springs, solved "
                   "quasistatically (Newton + line search, sparse Cholesky).")
      .def(py::init([](const TetMesh<>& mesh, const std::string& material, double density, const Vec3<>& gravity, double young, double poisson,
                       double mu10, double mu01, double kappa, double inversion_threshold, double relative_tolerance, Index max_iterations) {
             Body b;
             b.mesh = mesh;
             b.material = material;
             MaterialParameters p{young, poisson, mu10, mu01, kappa, inversion_threshold};
             b.elastic = with_material(material, p, [&](const auto& mat) -> std::unique_ptr<ElasticTerm> {
               return std::make_unique<ElasticTermOf<std::remove_cvref_t<decltype(mat)>>>(b.mesh, mat);
             });
             b.gravity = std::make_unique<Gravity<>>(b.mesh, density, gravity);
             b.bones = std::make_unique<BoneAttachments<>>(b.mesh.V);
             NewtonOptions o;
             o.relative_tolerance = relative_tolerance;
             o.max_iterations = max_iterations;
             b.solver = std::make_unique<Solver>(b.mesh.num_vertices(), b.mesh.T, o);
             return b;
           }),
           "mesh"_a, py::kw_only(), "material"_a = "neo_hookean", "density"_a = 1000.0, "gravity"_a = Vec3<>(0, 0, -9.81), "young"_a = 1e5,
           "poisson"_a = 0.45, "mu10"_a = 6e4, "mu01"_a = 2e4, "kappa"_a = 1.6e6, "inversion_threshold"_a = 0.1, "relative_tolerance"_a = 1e-6,
           "max_iterations"_a = 100,
           "material: neo_hookean or corotated (young, poisson) or mooney_rivlin (mu10, mu01, kappa); density in kg/m^3, gravity in m/s^2; "
           "Newton stops at |g| <= relative_tolerance x the forces in balance, or raises ConvergenceError after max_iterations.")
      .def_property_readonly("material", [](const Body& b) { return b.material; })
      .def_property_readonly("num_vertices", [](const Body& b) { return b.mesh.num_vertices(); })
      .def(
          "add_bone", [](Body& b, const std::string& name, const py::handle& vertices) { return b.bones->add_bone(name, vertex_list(vertices, "add_bone: vertices")); },
          "name"_a, "vertices"_a, "A rigid bone holding these vertices (Dirichlet: they follow its transform, identity until set).")
      .def(
          "set_bone_transform",
          [](Body& b, const std::string& name, const Mat3<>& R, const Vec3<>& t) { b.bones->set_transform(name, RigidTransform<>{R, t}); }, "name"_a,
          py::kw_only(), "R"_a = Mat3<>::Identity().eval(), "t"_a = Vec3<>::Zero().eval(), "x -> R x + t for the bone's vertices (R a rotation).")
      .def(
          "set_bone_hinge",
          [](Body& b, const std::string& name, const Vec3<>& point, const Vec3<>& axis, double angle) {
            b.bones->set_transform(name, hinge_rotation<double>(point, axis, angle));
          },
          "name"_a, "point"_a, "axis"_a, "angle"_a, "The bone rotated by angle (radians) about the axis through point (the jaw's hinge).")
      .def(
          "set_springs",
          [](Body& b, const py::handle& vertices, const py::handle& targets, const Eigen::Ref<const VecX<>>& weights) {
            b.springs = std::make_unique<VertexTargets<>>(
                VertexTargets<>::attraction(b.mesh.num_vertices(), vertex_list(vertices, "set_springs: vertices"), points_from(targets, "set_springs: targets"), weights));
          },
          "vertices"_a, "targets"_a, "weights"_a, "Springs E = sum_k w_k |x_{v_k} - target_k|^2 (w in J/m^2) replacing any before.")
      .def("clear_springs", [](Body& b) { b.springs.reset(); })
      .def(
          "solve",
          [](Body& b, std::optional<Points<>> x0, const std::string& policy) {
            Points<> x = x0 ? std::move(*x0) : b.mesh.V;
            if (x.rows() != b.mesh.num_vertices()) throw ShapeError("ElasticBody.solve: x0", {b.mesh.num_vertices(), 3}, {x.rows(), 3});
            NewtonReport r;
            {
              py::gil_scoped_release release;
              std::lock_guard lock(*b.mutex);
              r = b.elastic->solve(policy, *b.solver, x, b.bones->boundary(), *b.gravity, b.springs.get());
            }
            return py::make_tuple(py::cast(std::move(x)), report_dict(r));
          },
          "x0"_a = py::none(), py::kw_only(), policy_arg(),
          "The equilibrium positions (n, 3) from the warm start x0 (default: the rest shape), and the Newton report (a dict).")
      .def(
          "elastic_energy",
          [](Body& b, const Points<>& x, const std::string& policy) {
            if (x.rows() != b.mesh.num_vertices()) throw ShapeError("ElasticBody.elastic_energy: x", {b.mesh.num_vertices(), 3}, {x.rows(), 3});
            std::lock_guard lock(*b.mutex);
            return b.elastic->energy(policy, x);
          },
          "x"_a, py::kw_only(), policy_arg(), "The elastic energy (J) at positions x.");
}

}  // namespace simsr::python
