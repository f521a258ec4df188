#pragma once
/// \file
/// Candidate generation for point_assignment: exact 3-D kNN through nanoflann (1.4.3 API), with a
/// variable k per query. Kept local to the assignment so it does not depend on the order in which
/// the neighbours area's headers land.

#include <cmath>
#include <memory>
#include <vector>

#include <nanoflann.hpp>

#include "../../core/types.hpp"

namespace simsr::neighbors::detail {

/// Euclidean distance between rows a of A and b of B, in one fixed order of operations, so the
/// dense and sparse paths (and the tests) see bitwise-identical costs.
template <class DA, class DB>
inline double assignment_distance(const DA& A, Index a, const DB& B, Index b) {
  const double dx = double(A(a, 0)) - double(B(b, 0));
  const double dy = double(A(a, 1)) - double(B(b, 1));
  const double dz = double(A(a, 2)) - double(B(b, 2));
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

/// nanoflann kd-tree over an owned #P×3 row-major copy of the points.
class AssignmentKdTree {
 public:
  explicit AssignmentKdTree(Points<double> P) : cloud_{std::move(P)} {
    tree_ = std::make_unique<Tree>(3, cloud_, nanoflann::KDTreeSingleIndexAdaptorParams(12));
    tree_->buildIndex();
  }
  AssignmentKdTree(const AssignmentKdTree&) = delete;  // the tree points into cloud_
  AssignmentKdTree& operator=(const AssignmentKdTree&) = delete;
  Index size() const { return cloud_.P.rows(); }

  /// The k nearest points to q (k ≤ size()), ascending by squared distance: indices into idx,
  /// squared distances into d2 (both resized to k).
  void knn(const double* q, Index k, std::vector<std::size_t>& idx, std::vector<double>& d2) const {
    idx.resize(static_cast<std::size_t>(k));
    d2.resize(static_cast<std::size_t>(k));
    tree_->knnSearch(q, static_cast<std::size_t>(k), idx.data(), d2.data());
  }

 private:
  struct Cloud {
    Points<double> P;
    std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(P.rows()); }
    double kdtree_get_pt(std::size_t i, std::size_t d) const { return P(static_cast<Index>(i), static_cast<Index>(d)); }
    template <class BBox>
    bool kdtree_get_bbox(BBox&) const {
      return false;
    }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 3, std::size_t>;
  Cloud cloud_;
  std::unique_ptr<Tree> tree_;
};

}  // namespace simsr::neighbors::detail
