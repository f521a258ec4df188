/// \file
/// simsr's meshes and their geometry: TetMesh and TriMesh (their arrays are views into the object),
/// validation, volumes, areas, normals, the cotangent Laplacian and mass matrix (scipy.sparse),
/// quality, topology, Loop subdivision and the generators.
#include "common.hpp"

#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/mesh.hpp>

namespace simsr::python {
namespace {

NormalWeighting weighting_of(const std::string& w) {
  if (w == "angle") return NormalWeighting::angle;
  if (w == "area") return NormalWeighting::area;
  if (w == "uniform") return NormalWeighting::uniform;
  throw ArgumentError("normal weighting: expected 'angle', 'area' or 'uniform', got '" + w + "'");
}

py::dict report_dict(const MeshReport& r) {
  py::dict d;
  auto put = [&](const char* name, const ProblemCount& p) { d[name] = py::make_tuple(p.count, p.first); };
  put("non_finite_vertex", r.non_finite_vertex);
  put("unreferenced_vertex", r.unreferenced_vertex);
  put("out_of_range", r.out_of_range);
  put("repeated_vertex", r.repeated_vertex);
  put("degenerate", r.degenerate);
  put("inverted", r.inverted);
  d["ok"] = r.ok();
  d["summary"] = r.summary();
  return d;
}

const Tets& mesh_elements(const TetMesh<Scalar>& m) { return m.T; }
const Tris& mesh_elements(const TriMesh<Scalar>& m) { return m.F; }

ValidateOptions validate_options(double tolerance, bool allow_inverted) { return {tolerance, allow_inverted}; }

/// The validation and element methods both mesh classes share.
template <class Mesh, class Class>
void bind_common(Class& c, const char* element_name) {
  c.def_property_readonly("num_vertices", &Mesh::num_vertices)
      .def(
          "validate",
          [](const Mesh& mesh, double tolerance, bool allow_inverted, const std::string& policy) {
            with_policy(policy, [&](auto p) { validate(p, mesh, validate_options(tolerance, allow_inverted)); });
          },
          py::kw_only(), "degenerate_tolerance"_a = 1e-10, "allow_inverted"_a = false, policy_arg(),
          (std::string("Raises MeshError naming the first bad vertex or ") + element_name +
           " (non-finite, index out of range, repeated vertex, degenerate" + (std::string(element_name) == "tet" ? ", inverted)." : ")."))
              .c_str(),
          py::call_guard<py::gil_scoped_release>())
      .def(
          "check",
          [](const Mesh& mesh, double tolerance, const std::string& policy) {
            MeshReport r;
            {
              py::gil_scoped_release release;
              r = with_policy(policy, [&](auto p) { return check(p, mesh, validate_options(tolerance, false)); });
            }
            return report_dict(r);
          },
          py::kw_only(), "degenerate_tolerance"_a = 1e-10, policy_arg(),
          "Counts every problem: a dict of (count, first offending index) per kind, 'ok' and 'summary'.")
      .def(
          "quality", [](const Mesh& mesh, const std::string& policy) { return with_policy(policy, [&](auto p) { return element_quality(p, mesh.V, mesh_elements(mesh)); }); },
          py::kw_only(), policy_arg(), "Mean-ratio quality per element (1: regular, 0: degenerate).", py::call_guard<py::gil_scoped_release>());
}

}  // namespace

void bind_mesh(py::module_& m) {
  using Tet = TetMesh<Scalar>;
  using Tri = TriMesh<Scalar>;

  py::class_<Tet> tet(m, "TetMesh", "A tetrahedral mesh: V (n, 3) float64, T (t, 4) int32, positively oriented tets.");
  tet.def(py::init([](const py::handle& V, const py::handle& T) { return Tet{points_from(V, "TetMesh: V"), index_matrix<4>(T, "TetMesh: T")}; }),
          "V"_a, "T"_a, "Copies the arrays (T: any integer dtype within int32's range).")
      .def_property(
          "V", [](py::object self) { return view_of(self.cast<Tet&>().V, self); },
          [](Tet& t, const py::handle& V) { t.V = points_from(V, "TetMesh.V"); }, "(n, 3) positions: a writable view")
      .def_property(
          "T", [](py::object self) { return view_of(self.cast<Tet&>().T, self); },
          [](Tet& t, const py::handle& T) { t.T = index_matrix<4>(T, "TetMesh.T"); }, "(t, 4) tets: a view")
      .def_property_readonly("num_tets", &Tet::num_tets)
      .def(
          "signed_volumes", [](const Tet& t, const std::string& policy) { return with_policy(policy, [&](auto p) { return signed_volumes(p, t.V, t.T); }); },
          py::kw_only(), policy_arg(), "Signed volume per tet.", py::call_guard<py::gil_scoped_release>())
      .def(
          "volume", [](const Tet& t, const std::string& policy) { return with_policy(policy, [&](auto p) { return total_volume(p, t.V, t.T); }); },
          py::kw_only(), policy_arg(), "Total signed volume.", py::call_guard<py::gil_scoped_release>())
      .def("boundary_surface", [](const Tet& t) { return boundary_surface(t); }, "The boundary triangles (outward) over the same vertices.")
      .def("__repr__", [](const Tet& t) {
        return "<simsr.TetMesh " + std::to_string(t.num_vertices()) + " vertices, " + std::to_string(t.num_tets()) + " tets>";
      });
  bind_common<Tet>(tet, "tet");

  py::class_<Tri> tri(m, "TriMesh", "A triangle surface: V (n, 3) float64, F (f, 3) int32, counter-clockwise seen from outside.");
  tri.def(py::init([](const py::handle& V, const py::handle& F) { return Tri{points_from(V, "TriMesh: V"), index_matrix<3>(F, "TriMesh: F")}; }),
          "V"_a, "F"_a, "Copies the arrays (F: any integer dtype within int32's range).")
      .def_property(
          "V", [](py::object self) { return view_of(self.cast<Tri&>().V, self); },
          [](Tri& t, const py::handle& V) { t.V = points_from(V, "TriMesh.V"); }, "(n, 3) positions: a writable view")
      .def_property(
          "F", [](py::object self) { return view_of(self.cast<Tri&>().F, self); },
          [](Tri& t, const py::handle& F) { t.F = index_matrix<3>(F, "TriMesh.F"); }, "(f, 3) triangles: a view")
      .def_property_readonly("num_faces", &Tri::num_faces)
      .def(
          "face_areas", [](const Tri& t, const std::string& policy) { return with_policy(policy, [&](auto p) { return face_areas(p, t.V, t.F); }); },
          py::kw_only(), policy_arg(), py::call_guard<py::gil_scoped_release>())
      .def(
          "face_normals", [](const Tri& t, const std::string& policy) { return with_policy(policy, [&](auto p) { return face_normals(p, t.V, t.F); }); },
          py::kw_only(), policy_arg(), "Unit normal per triangle.", py::call_guard<py::gil_scoped_release>())
      .def(
          "vertex_normals", [](const Tri& t, const std::string& w) { return vertex_normals(t.V, t.F, weighting_of(w)); }, py::kw_only(),
          "weighting"_a = "angle", "Unit normal per vertex: incident triangle normals weighted by 'angle', 'area' or 'uniform'.",
          py::call_guard<py::gil_scoped_release>())
      .def("voronoi_areas", [](const Tri& t) { return voronoi_areas(t.V, t.F); }, "Mixed Voronoi area per vertex (Meyer et al. 2003).",
           py::call_guard<py::gil_scoped_release>())
      .def("barycentric_areas", [](const Tri& t) { return barycentric_areas(t.V, t.F); }, "A third of the incident triangles' areas per vertex.",
           py::call_guard<py::gil_scoped_release>())
      .def(
          "cotangent_laplacian",
          [](const Tri& t, const std::string& policy) { return with_policy(policy, [&](auto p) { return cotangent_laplacian(p, t.V, t.F); }); },
          py::kw_only(), policy_arg(), "The cotangent Laplacian (scipy.sparse, n x n, negative semi-definite: L_ii = -sum_j L_ij).",
          py::call_guard<py::gil_scoped_release>())
      .def(
          "mass_matrix",
          [](const Tri& t, const std::string& type) {
            if (type != "voronoi" && type != "barycentric") throw ArgumentError("mass_matrix: expected 'voronoi' or 'barycentric', got '" + type + "'");
            return mass_matrix(t.V, t.F, type == "voronoi" ? MassType::voronoi : MassType::barycentric);
          },
          "type"_a = "voronoi", "Lumped (diagonal) mass matrix, scipy.sparse.")
      .def("edges", [](const Tri& t) { return unique_edges(t.F); }, "Unique edges (e, 2), first index < second.")
      .def("boundary_edges", [](const Tri& t) { return boundary_edges(t.F); })
      .def("boundary_loops", [](const Tri& t) { return boundary_loops(t.F); }, "Each boundary loop's vertices in order.")
      .def(
          "loop_subdivision",
          [](const Tri& t, Index levels, double corner_degrees) {
            LoopSubdivision s;
            {
              py::gil_scoped_release release;
              s = loop_subdivision(t.V, t.F, levels, {corner_degrees});
            }
            Tri fine{(s.S * t.V).eval(), std::move(s.F)};
            return py::make_tuple(std::move(fine), std::move(s.S));
          },
          "levels"_a, py::kw_only(), "corner_degrees"_a = 30.0,
          "Loop subdivision: (fine TriMesh, S) with S the sparse (fine x coarse) map, fine.V = S @ V; boundary corners sharper than "
          "corner_degrees kept.")
      .def("__repr__", [](const Tri& t) {
        return "<simsr.TriMesh " + std::to_string(t.num_vertices()) + " vertices, " + std::to_string(t.num_faces()) + " triangles>";
      });
  bind_common<Tri>(tri, "triangle");

  // generators
  m.def(
      "box_tet_mesh",
      [](Index nx, Index ny, Index nz, const Vec3<Scalar>& lo, const Vec3<Scalar>& hi, const std::string& split) {
        if (split != "six" && split != "five") throw ArgumentError("box_tet_mesh: split must be 'six' or 'five', got '" + split + "'");
        return box_tet_mesh<Scalar>(nx, ny, nz, lo, hi, split == "six" ? CubeSplit::six : CubeSplit::five);
      },
      "nx"_a, "ny"_a, "nz"_a, "lo"_a = Vec3<Scalar>::Zero().eval(), "hi"_a = Vec3<Scalar>::Ones().eval(), py::kw_only(), "split"_a = "six",
      "The box [lo, hi] as nx x ny x nz cells of 6 (Kuhn) or 5 tets.");
  m.def("square_sheet", &square_sheet<Scalar>, "size"_a, "cells"_a, "A size x size square in the xy-plane, cells x cells squares cut criss-cross.");
  m.def("disk_surface", &disk_surface<Scalar>, "radius"_a, "rings"_a, "A flat disk of concentric rings in the xy-plane.");
  m.def("cylinder_tet_mesh", &cylinder_tet_mesh<Scalar>, "radius"_a, "height"_a, "radial"_a, "axial"_a);
  m.def("icosphere", &icosphere<Scalar>, "level"_a, "radius"_a = 1.0, "A subdivided icosahedron projected onto the sphere.");
  m.def("sphere_shell_tet_mesh", &sphere_shell_tet_mesh<Scalar>, "r_inner"_a, "r_outer"_a, "level"_a, "layers"_a);
  m.def("ellipsoid_surface", &ellipsoid_surface<Scalar>, "nv"_a, "a"_a, "b"_a, "c"_a);
}

}  // namespace simsr::python
