#pragma once
/// \file
/// The NeighborSearch concept: a point-set index built once and queried for k nearest neighbours
/// under an execution policy. KdTree (3-D) and BruteForceKnn (any dimension) satisfy it, so a
/// component can take its search as a template parameter:
///
///     template <simsr::neighbors::NeighborSearch Search> class Upsampler { Search search_; ... };
///     static_assert(simsr::neighbors::assert_neighbor_search<MySearch>());   // reasons as sentences

#include <concepts>

#include "../core/exec/policy.hpp"
#include "knn_result.hpp"

namespace simsr::neighbors {

namespace detail {

template <class T>
concept NamesItsTypes = requires {
  typename T::scalar_type;
  typename T::point_matrix;
};

template <class T>
concept BuildsOnPoints = NamesItsTypes<T> && std::default_initializable<T> && requires(T& s, const typename T::point_matrix& P) {
  s.build(P);
  { s.size() } -> std::convertible_to<Index>;
  { s.dim() } -> std::convertible_to<Index>;
};

template <class T>
concept QueriesK = NamesItsTypes<T> &&
    requires(T& s, const typename T::point_matrix& Q, Index k, KnnResult<typename T::scalar_type>& r) {
      s.query_into(exec::seq, Q, k, r);
      s.query_into(exec::omp, Q, k, r);
      { s.query(exec::seq, Q, k) } -> std::same_as<KnnResult<typename T::scalar_type>>;
    };

}  // namespace detail

/// A k-nearest-neighbour search over a point set: names `scalar_type` and `point_matrix`
/// (#P×D), is default-constructible, `build(P)` indexes P once, `size()`/`dim()` report #P and
/// D, `query_into(policy, Q, k, result)` fills a KnnResult (#Q×k, rows ascending) for
/// exec::seq and exec::omp, and `query(policy, Q, k)` returns one.
template <class T>
concept NeighborSearch = detail::NamesItsTypes<T> && detail::BuildsOnPoints<T> && detail::QueriesK<T>;

/// True for a NeighborSearch; for any other type a static_assert says which requirement fails.
template <class T>
constexpr bool assert_neighbor_search() {
  static_assert(detail::NamesItsTypes<T>,
                "This type is not a NeighborSearch: it must name its coordinate type as `scalar_type` and the "
                "point set it is built on as `point_matrix`.");
  static_assert(detail::BuildsOnPoints<T>,
                "This type is not a NeighborSearch: it must be default-constructible, index a point set with "
                "`build(points)` and report it with `size()` and `dim()`.");
  static_assert(detail::QueriesK<T>,
                "This type is not a NeighborSearch: it must answer `query_into(policy, queries, k, result)` into a "
                "KnnResult under exec::seq and exec::omp, and `query(policy, queries, k)` returning one.");
  return NeighborSearch<T>;
}

}  // namespace simsr::neighbors
