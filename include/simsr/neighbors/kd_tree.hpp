#pragma once
/// \file
/// Exact 3-D k-nearest neighbours with a nanoflann kd-tree: build once on #P×3 points, query
/// #Q×3 points under exec::seq or exec::omp.
///
///     simsr::neighbors::KdTree<double> tree(P);                 // P must outlive tree
///     auto r = tree.query(simsr::exec::omp, Q, 20);             // r.indices, r.distances: #Q×20
///     tree.query_into(simsr::exec::omp, Q, 20, r);              // reuses r: no allocation

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "../core/parallel.hpp"
#include "knn_result.hpp"
#include "nanoflann_compat.hpp"

namespace simsr::neighbors {

namespace detail {

/// nanoflann dataset adaptor over a borrowed row-major #P×3 array.
template <class S>
struct PointView3 {
  const S* data = nullptr;
  std::size_t n = 0;
  std::size_t kdtree_get_point_count() const { return n; }
  S kdtree_get_pt(compat::TreeIndex i, std::size_t d) const { return data[3 * static_cast<std::size_t>(i) + d]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};

/// nanoflann result set that writes the k best (squared distance, index) pairs, kept sorted in
/// (distance, index) order, straight into a result row. worstDist() is nudged one ulp up once the
/// set is full so that points tied with the current k-th are still offered and the smaller index
/// wins, whatever order the tree visits them in.
template <class S>
class SortedKnnSet {
 public:
  using DistanceType = S;
  using IndexType = compat::TreeIndex;
  using CountType = std::size_t;

  SortedKnnSet(VIndex* indices, S* dist2, std::size_t k) : idx_(indices), d2_(dist2), k_(k) {}

  std::size_t size() const { return count_; }
  bool empty() const { return count_ == 0; }
  bool full() const { return count_ == k_; }
  void sort() {}  // always sorted; newer nanoflann versions may call it

  bool addPoint(S d, IndexType i) {
    const VIndex vi = static_cast<VIndex>(i);
    if (full() && !closer(d, vi, d2_[k_ - 1], idx_[k_ - 1])) return true;
    std::size_t j = count_ < k_ ? count_++ : k_ - 1;
    for (; j > 0 && closer(d, vi, d2_[j - 1], idx_[j - 1]); --j) {
      d2_[j] = d2_[j - 1];
      idx_[j] = idx_[j - 1];
    }
    d2_[j] = d;
    idx_[j] = vi;
    return true;
  }

  S worstDist() const {
    return full() ? std::nextafter(d2_[k_ - 1], std::numeric_limits<S>::infinity()) : std::numeric_limits<S>::max();
  }

 private:
  VIndex* idx_;
  S* d2_;
  std::size_t k_;
  std::size_t count_ = 0;
};

/// A result row of k squared distances in (distance, index) order → Euclidean distances; distinct
/// squared distances may share a square root, and then the smaller index comes first.
template <class S>
void finish_knn_row(VIndex* idx, S* dist, Index k) {
  for (Index j = 0; j < k; ++j) {
    dist[j] = std::sqrt(dist[j]);
    for (Index t = j; t > 0 && dist[t] == dist[t - 1] && idx[t] < idx[t - 1]; --t) std::swap(idx[t], idx[t - 1]);
  }
}

}  // namespace detail

/// Exact Euclidean kNN in 3-D over a point set indexed once (S = float or double).
///
/// Lifetime: the tree borrows the points (a view, no copy); they must stay alive and unchanged
/// while the tree is used. Rebuild with build() after moving them. Passing a temporary is a
/// compile error.
///
/// Thread safety: queries are const and only read the tree (nanoflann's searches are read-only
/// once built), so any number of threads may query one tree at once; build() must not overlap
/// with queries. query_into under exec::omp splits the queries over OpenMP threads; each row is
/// computed the same way under seq and omp, so the results are bitwise identical.
///
/// Ties: neighbours at equal distance come by ascending index (the boundary of the k is decided on
/// squared distances, where an equal one also goes to the smaller index).
template <class S = Scalar>
class KdTree {
  static_assert(std::is_same_v<S, float> || std::is_same_v<S, double>, "simsr::neighbors::KdTree works on float or double points");

 public:
  using scalar_type = S;
  using point_matrix = Points<S>;  ///< #P×3, row-major
  static constexpr Index dimension = 3;

  struct Params {
    std::size_t leaf_max_size = 10;  ///< points per leaf (nanoflann's default; 10–20 are all close)
  };

  KdTree() = default;
  explicit KdTree(const point_matrix& P, Params params = {}) { build(P, params); }
  explicit KdTree(Eigen::Map<const point_matrix> P, Params params = {}) { build(P, params); }
  KdTree(point_matrix&&, Params = {}) = delete;  // the tree would outlive the points

  /// Indexes P (#P×3, borrowed). Throws ArgumentError for a non-finite coordinate.
  void build(const point_matrix& P, Params params = {}) { build_view(P.data(), P.rows(), params); }
  void build(Eigen::Map<const point_matrix> P, Params params = {}) { build_view(P.data(), P.rows(), params); }
  void build(point_matrix&&, Params = {}) = delete;

  /// Number of indexed points #P (0 before build).
  Index size() const { return impl_ ? static_cast<Index>(impl_->data.n) : 0; }
  Index dim() const { return dimension; }

  /// k nearest indexed points of every row of Q (#Q×3, any scalar type) into `out` (resized to
  /// #Q×k; no allocation when already that shape). Throws ArgumentError when k < 1, k > #P or a
  /// query is not finite; ShapeError when Q is not #Q×3.
  template <exec::HostPolicy Policy, class DQ>
  void query_into(Policy policy, const Eigen::MatrixBase<DQ>& Q, Index k, KnnResult<S>& out) const {
    constexpr const char* where = "neighbors::KdTree::query";
    detail::check_cols(where, "queries", Q, 3);
    detail::check_k(where, k, size(), "indexed points");
    out.resize(Q.rows(), k);
    const auto& tree = impl_->tree;
    const auto params = compat::search_params();
    exec::parallel_for(policy, Q.rows(), [&](Index i) {
      S q[3];
      for (int d = 0; d < 3; ++d) {
        q[d] = static_cast<S>(Q(i, d));
        if (!std::isfinite(q[d]))
          throw ArgumentError(std::string(where) + ": query row " + std::to_string(i) + " holds a non-finite coordinate");
      }
      S* dist = out.distances.row(i).data();
      detail::SortedKnnSet<S> set(out.indices.row(i).data(), dist, static_cast<std::size_t>(k));
      tree.findNeighbors(set, q, params);
      detail::finish_knn_row(out.indices.row(i).data(), dist, k);
    });
  }

  /// As query_into, returning a new result.
  template <exec::HostPolicy Policy, class DQ>
  KnnResult<S> query(Policy policy, const Eigen::MatrixBase<DQ>& Q, Index k) const {
    KnnResult<S> r;
    query_into(policy, Q, k, r);
    return r;
  }

  /// Indexed points strictly closer than `radius` (Euclidean) to the point q (3 values) into
  /// `out` as (index, distance), ascending by distance then index. Reuses a per-thread buffer.
  template <class DQ>
  void radius_into(const Eigen::MatrixBase<DQ>& q, S radius, std::vector<std::pair<VIndex, S>>& out) const {
    constexpr const char* where = "neighbors::KdTree::radius";
    if (q.size() != 3) throw ShapeError(std::string(where) + ": query point", {3}, {q.size()});
    if (!(radius >= 0) || !std::isfinite(radius)) throw ArgumentError(std::string(where) + ": radius must be finite and >= 0");
    out.clear();
    if (!impl_) return;
    S p[3];
    for (int d = 0; d < 3; ++d) {
      p[d] = static_cast<S>(q(d));
      if (!std::isfinite(p[d])) throw ArgumentError(std::string(where) + ": query point holds a non-finite coordinate");
    }
    thread_local std::vector<compat::RadiusItem<compat::TreeIndex, S>> hits;
    hits.clear();
    impl_->tree.radiusSearch(p, radius * radius, hits, compat::search_params(false));
    for (const auto& h : hits) out.emplace_back(static_cast<VIndex>(h.first), h.second);
    std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return detail::closer(a.second, a.first, b.second, b.first); });
    for (auto& o : out) o.second = std::sqrt(o.second);
  }

 private:
  using Dataset = detail::PointView3<S>;
  using Tree = compat::L2Tree<S, Dataset, 3>;
  struct Impl {  // the tree keeps a reference to `data`: both live at one stable address
    Dataset data;
    Tree tree;
    Impl(const S* p, std::size_t n, std::size_t leaf) : data{p, n}, tree(3, data, compat::tree_params(leaf)) {}
  };

  void build_view(const S* data, Index n, Params params) {
    if (params.leaf_max_size < 1) throw ArgumentError("neighbors::KdTree::build: leaf_max_size must be at least 1");
    if (n > Index(std::numeric_limits<VIndex>::max()))
      throw ArgumentError("neighbors::KdTree::build: " + std::to_string(n) + " points exceed the 32-bit index range");
    detail::check_finite_rows("neighbors::KdTree::build", "points", Eigen::Map<const point_matrix>(data, n, 3));
    impl_.reset();
    impl_ = std::make_unique<Impl>(data, static_cast<std::size_t>(n), params.leaf_max_size);
  }

  std::unique_ptr<Impl> impl_;
};

}  // namespace simsr::neighbors
