#pragma once
/// \file
/// The upsampling neighbourhoods of Park et al. (2023, §3.2, Fig. 3): for every HR surface vertex,
/// the k (= 20) nearest LR vertices by geodesic distance over the HR surface. Each LR vertex is
/// first mapped one-to-one onto an HR vertex (minimum total Euclidean distance, assign_points);
/// then a k-label multi-source Dijkstra over the HR surface edges (rest lengths) finds, for every
/// HR vertex, its k nearest mapped LR vertices. Computed once on the rest shapes, saved, reloaded.
///
///     auto nb = simsr::neighbors::upsampling_neighborhoods(simsr::exec::omp, lr.V, hr.V, hr.F);
///     // nb.indices(j, 0..19): LR vertex ids nearest to HR vertex j; nb.distances(j, ·) ascending
///     simsr::neighbors::save_upsampling_neighborhoods("neighbors.npz", nb);
///     auto again = simsr::neighbors::load_upsampling_neighborhoods("neighbors.npz");

#include <filesystem>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../io/npz.hpp"
#include "detail/dijkstra_k_nearest_sources.hpp"
#include "point_assignment.hpp"

namespace simsr::neighbors {

/// k nearest sources of every vertex of a graph: `indices` #V×k source ids, `distances` #V×k
/// path lengths (units of the vertex positions), rows ascending by (distance, source id).
struct GeodesicSources {
  Eigen::Matrix<VIndex, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> indices;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> distances;
};

/// The k nearest of the sources (source s at vertex `source_vertex[s]`) from every vertex of the
/// surface (V #V×3, F #F×3), along its edges with lengths measured in V; ties by source id.
/// Distances are bitwise those of one Dijkstra per source. Throws ShapeError (shapes),
/// ArgumentError (k outside [1, #sources], a source vertex outside [0, #V)), MeshError (kind
/// "vertex") naming the first vertex that reaches fewer than k sources (disconnected surface).
/// O(#V·k·deg·log) time, sequential (a single priority queue).
template <class DV, class DF>
GeodesicSources geodesic_k_nearest_sources(const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DF>& F,
                                           const IndexVector& source_vertex, Index k) {
  if (V.cols() != 3) throw ShapeError("geodesic_k_nearest_sources: V", {-1, 3}, {V.rows(), V.cols()});
  if (F.cols() != 3) throw ShapeError("geodesic_k_nearest_sources: F", {-1, 3}, {F.rows(), F.cols()});
  const Index ns = source_vertex.size(), nv = V.rows();
  if (k < 1 || k > ns)
    throw ArgumentError("geodesic_k_nearest_sources: k = " + std::to_string(k) + " outside [1, " + std::to_string(ns) +
                        "] (the number of sources)");
  for (Index s = 0; s < ns; ++s)
    if (source_vertex[s] < 0 || source_vertex[s] >= nv)
      throw ArgumentError("geodesic_k_nearest_sources: source " + std::to_string(s) + " at vertex " +
                          std::to_string(source_vertex[s]) + " outside [0, " + std::to_string(nv) + ")");
  const WeightedGraph g = surface_edge_graph(V, F);
  GeodesicSources out;
  out.indices.resize(nv, k);
  out.distances.resize(nv, k);
  const auto count = detail::k_nearest_sources(g, std::span<const VIndex>(source_vertex.data(), std::size_t(ns)), k,
                                               out.indices.data(), out.distances.data());
  for (Index v = 0; v < nv; ++v)
    if (count[v] < k)
      throw MeshError("vertex", v,
                      "reaches only " + std::to_string(count[v]) + " of the k = " + std::to_string(k) +
                          " sources over the surface edges (disconnected surface?)");
  return out;
}

/// Parameters of upsampling_neighborhoods.
struct UpsamplingOptions {
  Index k = 20;                       ///< neighbours per HR vertex (the paper's k)
  PointAssignmentOptions assignment;  ///< LR→HR mapping
};

/// Upsampling neighbourhoods (§3.2) of an HR surface with M vertices for N ≤ M LR vertices.
struct UpsamplingNeighborhoods {
  /// M×k LR vertex ids, nearest first (ties by id)
  Eigen::Matrix<VIndex, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> indices;
  /// M×k geodesic distances over the HR rest surface (units of the positions), ascending
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> distances;
  IndexVector lr_to_hr;            ///< N: HR vertex each LR vertex is mapped onto (distinct)
  double assignment_cost = 0;      ///< Σ_i |x_i^L − x_{lr_to_hr[i]}^H|
  bool assignment_globally_optimal = false;  ///< the mapping is provably a global optimum
  std::vector<std::string> log;    ///< assignment rounds (see assign_points)

  Index k() const { return indices.cols(); }
};

/// Computes the upsampling neighbourhoods from the LR rest vertices (N×3) and the HR rest surface
/// (M×3 vertices, #F×3 triangles). `policy` runs the candidate search of the assignment; results
/// are identical under seq and omp. Throws as assign_points and geodesic_k_nearest_sources.
template <exec::HostPolicy Policy, class DL, class DH, class DF>
UpsamplingNeighborhoods upsampling_neighborhoods(Policy policy, const Eigen::MatrixBase<DL>& lr_vertices,
                                                 const Eigen::MatrixBase<DH>& hr_vertices,
                                                 const Eigen::MatrixBase<DF>& hr_faces, const UpsamplingOptions& options = {}) {
  PointAssignment a = assign_points(policy, lr_vertices, hr_vertices, options.assignment);
  GeodesicSources s = geodesic_k_nearest_sources(hr_vertices, hr_faces, a.row_to_col, options.k);
  UpsamplingNeighborhoods nb;
  nb.indices = std::move(s.indices);
  nb.distances = std::move(s.distances);
  nb.lr_to_hr = std::move(a.row_to_col);
  nb.assignment_cost = a.total_cost;
  nb.assignment_globally_optimal = a.globally_optimal;
  nb.log = std::move(a.log);
  return nb;
}

/// The arrays of `nb` as saved: `indices` (M×k int64), `distances` (M×k float64), `lr_to_hr`
/// (N int64), `assignment_cost` (0-d float64), `assignment_globally_optimal` (0-d bool). Callers
/// may add arrays (the `simsr neighbors` tool adds the LR geodesic graph) before writing.
inline io::NpzArrays upsampling_neighborhoods_arrays(const UpsamplingNeighborhoods& nb) {
  io::NpzArrays z;
  z["indices"] = io::make_npy(nb.indices.cast<std::int64_t>().eval());
  z["distances"] = io::make_npy(nb.distances);
  z["lr_to_hr"] = io::make_npy(nb.lr_to_hr.cast<std::int64_t>().eval());
  z["assignment_cost"] = io::make_npy<double>({}, &nb.assignment_cost);
  const bool opt = nb.assignment_globally_optimal;
  z["assignment_globally_optimal"] = io::make_npy<bool>({}, &opt);
  return z;
}

/// Writes `nb` as a compressed .npz (see upsampling_neighborhoods_arrays for the arrays).
inline void save_upsampling_neighborhoods(const std::filesystem::path& path, const UpsamplingNeighborhoods& nb) {
  io::write_npz(path, upsampling_neighborhoods_arrays(nb), io::NpzCompression::Deflate);
}

/// Reads what save_upsampling_neighborhoods wrote. Throws ParseError (unreadable file), ArgumentError
/// (a missing array, or an index outside its range) and ShapeError (inconsistent shapes).
inline UpsamplingNeighborhoods load_upsampling_neighborhoods(const std::filesystem::path& path) {
  io::NpzReader z(path);
  UpsamplingNeighborhoods nb;
  nb.indices = z.read("indices").to_matrix<VIndex>();
  nb.distances = z.read("distances").to_matrix<double>();
  const auto map = z.read("lr_to_hr");
  if (map.ndim() != 1) throw ShapeError(path.string() + ": lr_to_hr", {-1}, map.shape);
  nb.lr_to_hr = map.to_matrix<VIndex>().col(0);
  nb.assignment_cost = z.read("assignment_cost").item<double>();
  nb.assignment_globally_optimal = z.read("assignment_globally_optimal").item<bool>();
  const Index m = nb.indices.rows(), n = nb.lr_to_hr.size();
  if (nb.distances.rows() != m || nb.distances.cols() != nb.indices.cols())
    throw ShapeError(path.string() + ": distances (as indices)", {m, nb.indices.cols()},
                     {nb.distances.rows(), nb.distances.cols()});
  for (Index i = 0; i < nb.indices.size(); ++i)
    if (nb.indices.data()[i] < 0 || nb.indices.data()[i] >= n)
      throw ArgumentError(path.string() + ": indices entry " + std::to_string(i) + " = " +
                          std::to_string(nb.indices.data()[i]) + " outside [0, " + std::to_string(n) + ") (LR vertices)");
  for (Index i = 0; i < n; ++i)
    if (nb.lr_to_hr[i] < 0 || nb.lr_to_hr[i] >= m)
      throw ArgumentError(path.string() + ": lr_to_hr[" + std::to_string(i) + "] = " + std::to_string(nb.lr_to_hr[i]) +
                          " outside [0, " + std::to_string(m) + ") (HR vertices)");
  return nb;
}

}  // namespace simsr::neighbors
