/// \file
/// simsr.neighbors: the k-d tree (nanoflann) for 3-D points, the exact brute-force kNN for
/// features of any dimension (float32, as the network's dynamic graph), geodesic kNN along mesh
/// edges, and the §3.2 upsampling neighbourhoods (with their files). The searched points are
/// borrowed by the C++ search object: the Python object keeps a float64 (or float32) C-ordered
/// array of them alive (the caller's own array when it already is one: no copy).
#include "common.hpp"

#include <simsr/neighbors/neighbors.hpp>

namespace simsr::python {
namespace {

template <class S>
using KnnResultOf = neighbors::KnnResult<S>;

template <class S>
void bind_knn_result(py::module_& m, const char* name) {
  using R = KnnResultOf<S>;
  py::class_<R>(m, name, "k nearest neighbours per query: indices (q, k) int32 and distances (q, k), each row ascending (ties by index).")
      .def(py::init<>(), "An empty result, to be filled by query_into (reused without allocating when the shape repeats).")
      .def_property_readonly("indices", [](py::object self) { return view_of(self.cast<R&>().indices, self); })
      .def_property_readonly("distances", [](py::object self) { return view_of(self.cast<R&>().distances, self); })
      .def_property_readonly("k", &R::k)
      .def("__len__", &R::queries)
      .def("__iter__", [](py::object self) {  // indices, distances = result
        return py::iter(py::make_tuple(self.attr("indices"), self.attr("distances")));
      });
}

/// A k-d tree over 3-D points, holding the array it borrows.
struct PyKdTree {
  using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
  Array points;
  neighbors::KdTree<double> tree;

  PyKdTree(const py::handle& P, std::size_t leaf) : points(Array::ensure(P)) {
    if (!points || points.ndim() != 2 || points.shape(1) != 3)
      throw ShapeError("KdTree: points", {-1, 3}, points ? std::vector<std::int64_t>(points.shape(), points.shape() + points.ndim()) : std::vector<std::int64_t>{});
    tree.build(Eigen::Map<const Points<>>(points.data(), points.shape(0), 3), {leaf});
  }
};

/// The exact brute-force kNN over N×D float32 features, holding the array it borrows.
struct PyBruteForce {
  using Array = py::array_t<float, py::array::c_style | py::array::forcecast>;
  using Matrix = neighbors::BruteForceKnn<float>::point_matrix;
  Array points;
  neighbors::BruteForceKnn<float> knn;

  explicit PyBruteForce(const py::handle& P) : points(Array::ensure(P)) {
    if (!points || points.ndim() != 2)
      throw ShapeError("BruteForceKnn: points (N, D)", {-1, -1}, points ? std::vector<std::int64_t>(points.shape(), points.shape() + points.ndim()) : std::vector<std::int64_t>{});
    knn.build(Eigen::Map<const Matrix>(points.data(), points.shape(0), points.shape(1)));
  }
};

using QueryRef = Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;
using FeatureRef = Eigen::Ref<const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;

}  // namespace

void bind_neighbors(py::module_& m) {
  bind_knn_result<double>(m, "KnnResult");
  bind_knn_result<float>(m, "KnnResult32");

  py::class_<PyKdTree>(m, "KdTree", "A k-d tree (nanoflann) over 3-D points; queries return exact Euclidean kNN.")
      .def(py::init<const py::handle&, std::size_t>(), "points"_a, "leaf_max_size"_a = 10)
      .def_property_readonly("size", [](const PyKdTree& t) { return t.tree.size(); })
      .def(
          "query",
          [](const PyKdTree& t, const QueryRef& Q, Index k, const std::string& policy) {
            py::gil_scoped_release release;
            return with_policy(policy, [&](auto p) { return t.tree.query(p, Q, k); });
          },
          "queries"_a, "k"_a, py::kw_only(), policy_arg(), "The k nearest points of each query row (q, 3): a KnnResult.")
      .def(
          "query_into",
          [](const PyKdTree& t, const QueryRef& Q, Index k, KnnResultOf<double>& out, const std::string& policy) {
            // a reused result keeps its shape: resizing it would free the buffer that views of it read
            if (out.indices.size() > 0 && (out.queries() != Q.rows() || out.k() != k))
              throw ShapeError("KdTree.query_into: out (a reused result keeps its shape; take a new KnnResult for another)", {Q.rows(), k},
                               {out.queries(), out.k()});
            py::gil_scoped_release release;
            with_policy(policy, [&](auto p) { t.tree.query_into(p, Q, k, out); });
          },
          "queries"_a, "k"_a, "out"_a, py::kw_only(), policy_arg(),
          "As query, into a KnnResult that is new or has this shape (then nothing is allocated and views of it stay valid).")
      .def(
          "radius",
          [](const PyKdTree& t, const Vec3<double>& q, double r) {
            std::vector<std::pair<VIndex, double>> hits;
            t.tree.radius_into(q, r, hits);
            Eigen::Matrix<VIndex, Eigen::Dynamic, 1> idx(Index(hits.size()));
            Eigen::VectorXd dist(Index(hits.size()));
            for (std::size_t i = 0; i < hits.size(); ++i) idx[Index(i)] = hits[i].first, dist[Index(i)] = hits[i].second;
            return py::make_tuple(std::move(idx), std::move(dist));
          },
          "point"_a, "radius"_a, "(indices, distances) of the points strictly closer than radius, ascending.");

  py::class_<PyBruteForce>(m, "BruteForceKnn",
                           "Exact kNN over (N, D) float32 features by blocked GEMMs with an exact re-ranking (the network's dynamic graph).")
      .def(py::init<const py::handle&>(), "points"_a)
      .def_property_readonly("size", [](const PyBruteForce& b) { return b.knn.size(); })
      .def_property_readonly("dim", [](const PyBruteForce& b) { return b.knn.dim(); })
      .def(
          "query",
          [](PyBruteForce& b, const FeatureRef& Q, Index k, const std::string& policy) {
            py::gil_scoped_release release;
            return with_policy(policy, [&](auto p) { return b.knn.query(p, Q, k); });
          },
          "queries"_a, "k"_a, py::kw_only(), policy_arg())
      .def(
          "query_self",
          [](PyBruteForce& b, Index k, bool exclude_self, const std::string& policy) {
            py::gil_scoped_release release;
            return with_policy(policy, [&](auto p) { return b.knn.query_self(p, k, exclude_self); });
          },
          "k"_a, py::kw_only(), "exclude_self"_a = true, policy_arg(), "The k nearest other points of every point (self first when included).");

  m.def(
      "geodesic_knn",
      [](const Eigen::Ref<const Points<>>& V, const py::handle& E, Index k, const std::string& policy) {
        py::array a = py::array::ensure(E);
        if (!a || a.ndim() != 2) throw ShapeError("geodesic_knn: elements (e, 2|3|4)", {-1, -1}, a ? std::vector<std::int64_t>(a.shape(), a.shape() + a.ndim()) : std::vector<std::int64_t>{});
        const auto run = [&](const auto& elements) {
          py::gil_scoped_release release;
          return with_policy(policy, [&](auto p) { return neighbors::geodesic_knn<double>(p, V, elements, k); });
        };
        switch (a.shape(1)) {
          case 2: return run(index_matrix<2>(E, "geodesic_knn: edges"));
          case 3: return run(index_matrix<3>(E, "geodesic_knn: triangles"));
          case 4: return run(index_matrix<4>(E, "geodesic_knn: tets"));
          default: throw ShapeError("geodesic_knn: elements (e, 2|3|4)", {-1, -1}, {a.shape(0), a.shape(1)});
        }
      },
      "V"_a, "elements"_a, "k"_a, py::kw_only(), policy_arg(),
      "The k nearest vertices of every vertex (self first) by shortest paths along the edges of the elements (edges, triangles or tets).");

  using NB = neighbors::UpsamplingNeighborhoods;
  py::class_<NB>(m, "UpsamplingNeighborhoods",
                 "The paper's §3.2 neighbourhoods: per HR vertex its k LR vertices nearest over the HR surface (indices (M, k), distances).")
      .def_property_readonly("indices", [](py::object self) { return view_of(self.cast<NB&>().indices, self); })
      .def_property_readonly("distances", [](py::object self) { return view_of(self.cast<NB&>().distances, self); })
      .def_property_readonly("lr_to_hr", [](py::object self) { return view_of(self.cast<NB&>().lr_to_hr, self); },
                             "The HR vertex each LR vertex is assigned to (distinct).")
      .def_readonly("assignment_cost", &NB::assignment_cost)
      .def_readonly("assignment_globally_optimal", &NB::assignment_globally_optimal)
      .def_readonly("log", &NB::log)
      .def_property_readonly("k", &NB::k)
      .def("save", [](const NB& nb, const std::filesystem::path& path) { neighbors::save_upsampling_neighborhoods(path, nb); }, "path"_a,
           "Writes them as a compressed .npz, atomically.");
  m.def("load_upsampling_neighborhoods", &neighbors::load_upsampling_neighborhoods, "path"_a);
  m.def(
      "upsampling_neighborhoods",
      [](const Eigen::Ref<const Points<>>& lr_vertices, const TriMesh<Scalar>& hr, Index k, const std::string& policy) {
        neighbors::UpsamplingOptions o;
        o.k = k;
        py::gil_scoped_release release;
        return with_policy(policy, [&](auto p) { return neighbors::upsampling_neighborhoods(p, lr_vertices, hr.V, hr.F, o); });
      },
      "lr_vertices"_a, "hr"_a, "k"_a = 20, py::kw_only(), policy_arg(),
      "LR vertices assigned one-to-one to HR vertices (min-cost), then the k assigned LR vertices nearest to every HR vertex over the HR "
      "surface (Dijkstra).");
}

}  // namespace simsr::python
