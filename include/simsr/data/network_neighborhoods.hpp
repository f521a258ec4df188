#pragma once
/// \file
/// The neighbourhoods a super-resolution network needs beyond the rest shapes: the §3.2
/// upsampling neighbourhoods (M×upK LR ids of each HR vertex with geodesic distances) and the LR
/// graph of the first EdgeConv (N×k LR ids, self first). Three sources, one result:
///
///     auto nb = data::read_official_neighborhoods("../shared/data/bunny", N, M);  // the authors' geo_dist_*.npy
///     auto nb = data::read_network_neighborhoods("N.npz", N, M);                 // what `simsr neighbors` wrote
///     auto nb = data::compute_network_neighborhoods(exec::omp, lr, hr, 20, 20);  // assignment + Dijkstra here
///     data::save_network_neighborhoods("N.npz", nb);
///
/// Every reader checks the shapes against N and M and every index against its range.

#include <filesystem>
#include <string>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../io/npy.hpp"
#include "../io/npz.hpp"
#include "../mesh/tet_mesh.hpp"
#include "../mesh/tri_mesh.hpp"
#include "../neighbors/geodesic_knn.hpp"
#include "../neighbors/upsampling_neighborhoods.hpp"

namespace simsr::data {

/// Neighbour ids, one row per vertex.
using NeighborIndices = Eigen::Matrix<VIndex, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// The network's neighbourhoods (see the file comment).
struct NetworkNeighborhoods {
  neighbors::UpsamplingNeighborhoods upsampling;  ///< M×upK ids + distances (lr_to_hr when computed or saved by simsr)
  NeighborIndices lr_graph;                       ///< N×k LR geodesic neighbours, self first
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> lr_distances;  ///< N×k (empty from the official files)
  std::string source;                             ///< where they came from, for logs and reports
};

namespace detail {
inline void check_ids(const std::string& what, const NeighborIndices& ids, Index rows, Index range) {
  if (ids.rows() != rows) throw ShapeError(what, {rows, -1}, {ids.rows(), ids.cols()});
  for (Index i = 0; i < ids.size(); ++i)
    if (ids.data()[i] < 0 || ids.data()[i] >= range)
      throw ArgumentError(what + ": entry (" + std::to_string(i / std::max<Index>(1, ids.cols())) + ", " +
                          std::to_string(i % std::max<Index>(1, ids.cols())) + ") = " + std::to_string(ids.data()[i]) +
                          " outside [0, " + std::to_string(range) + ")");
}

inline io::NpyArray read_matrix_npy(const std::filesystem::path& p, Index rows) {
  io::NpyArray a = io::read_npy(p);
  if (a.ndim() != 2 || a.shape[0] != rows) throw ShapeError(p.string(), {rows, -1}, a.shape);
  return a;
}

}  // namespace detail

/// Throws (naming nb.source) unless the neighbourhoods fit N LR and M HR vertices: shapes, every
/// index within its range, distances finite and non-negative.
inline void check_network_neighborhoods(const NetworkNeighborhoods& nb, Index num_lr, Index num_hr) {
  using detail::check_ids;
  const auto& up = nb.upsampling;
  check_ids(nb.source + ": upsampling indices (M×upK)", up.indices, num_hr, num_lr);
  if (up.distances.rows() != num_hr || up.distances.cols() != up.indices.cols())
    throw ShapeError(nb.source + ": upsampling distances (as the indices)", {num_hr, up.indices.cols()}, {up.distances.rows(), up.distances.cols()});
  if (!up.distances.allFinite() || (up.distances.size() > 0 && up.distances.minCoeff() < 0))
    throw ArgumentError(nb.source + ": upsampling distances must be finite and non-negative");
  check_ids(nb.source + ": LR graph (N×k)", nb.lr_graph, num_lr, num_lr);
}

/// The authors' files in `dir`: geo_dist_surf2tet_idx.npy (M×K ids), geo_dist_surf2tet.npy (M×K
/// distances) and geo_dist_tet2tet_idx.npy (N×K LR graph), as shipped with the bunny example.
inline NetworkNeighborhoods read_official_neighborhoods(const std::filesystem::path& dir, Index num_lr, Index num_hr) {
  NetworkNeighborhoods nb;
  nb.source = "official files in " + dir.string();
  nb.upsampling.indices = detail::read_matrix_npy(dir / "geo_dist_surf2tet_idx.npy", num_hr).to_matrix<VIndex>();
  nb.upsampling.distances = detail::read_matrix_npy(dir / "geo_dist_surf2tet.npy", num_hr).to_matrix<double>();
  nb.lr_graph = detail::read_matrix_npy(dir / "geo_dist_tet2tet_idx.npy", num_lr).to_matrix<VIndex>();
  check_network_neighborhoods(nb, num_lr, num_hr);
  return nb;
}

/// Computes both: the §3.2 neighbourhoods with `up_k` columns (assignment + k-label Dijkstra) and
/// the LR geodesic graph with `lr_k` columns (Dijkstra over the LR mesh edges, self first).
template <exec::HostPolicy Policy>
NetworkNeighborhoods compute_network_neighborhoods(Policy policy, const TetMesh<Scalar>& lr, const TriMesh<Scalar>& hr, Index up_k, Index lr_k) {
  if (up_k < 1 || lr_k < 1) throw ArgumentError("network neighbourhoods: k must be ≥ 1 (upsampling " + std::to_string(up_k) + ", LR graph " + std::to_string(lr_k) + ")");
  NetworkNeighborhoods nb;
  neighbors::UpsamplingOptions o;
  o.k = up_k;
  nb.upsampling = neighbors::upsampling_neighborhoods(policy, lr.V, hr.V, hr.F, o);
  const auto g = neighbors::geodesic_knn(policy, lr.V, lr.T, lr_k);
  nb.lr_graph = g.indices;
  nb.lr_distances = g.distances.template cast<double>();
  nb.source = "computed (assignment + k-label Dijkstra; LR geodesic kNN)";
  return nb;
}

/// The arrays save_network_neighborhoods writes: upsampling_neighborhoods_arrays (indices,
/// distances, lr_to_hr, …) plus lr_indices (N×k int64) and lr_distances (N×k float64).
inline io::NpzArrays network_neighborhoods_arrays(const NetworkNeighborhoods& nb) {
  io::NpzArrays z = neighbors::upsampling_neighborhoods_arrays(nb.upsampling);
  z["lr_indices"] = io::make_npy(nb.lr_graph.cast<std::int64_t>().eval());
  z["lr_distances"] = io::make_npy(nb.lr_distances);
  return z;
}

/// Writes `nb` as a compressed .npz (the `simsr neighbors` file).
inline void save_network_neighborhoods(const std::filesystem::path& file, const NetworkNeighborhoods& nb) {
  io::write_npz(file, network_neighborhoods_arrays(nb), io::NpzCompression::Deflate);
}

/// Reads what save_network_neighborhoods (`simsr neighbors`) wrote, checked against N and M.
inline NetworkNeighborhoods read_network_neighborhoods(const std::filesystem::path& file, Index num_lr, Index num_hr) {
  NetworkNeighborhoods nb;
  nb.source = file.string();
  nb.upsampling = neighbors::load_upsampling_neighborhoods(file);
  io::NpzReader z(file);
  if (!z.contains("lr_indices")) throw ArgumentError(file.string() + ": no 'lr_indices' (the LR geodesic graph that `simsr neighbors` writes)");
  const io::NpyArray li = z.read("lr_indices");
  if (li.ndim() != 2) throw ShapeError(file.string() + ": lr_indices", {num_lr, -1}, li.shape);
  nb.lr_graph = li.to_matrix<VIndex>();
  if (z.contains("lr_distances")) nb.lr_distances = z.read("lr_distances").to_matrix<double>();
  if (nb.upsampling.lr_to_hr.size() != num_lr)
    throw ShapeError(file.string() + ": lr_to_hr (one HR vertex per LR vertex)", {num_lr}, {nb.upsampling.lr_to_hr.size()});
  check_network_neighborhoods(nb, num_lr, num_hr);
  return nb;
}

}  // namespace simsr::data
