#pragma once
/// \file
/// The one place that knows nanoflann's version. Debian ships 1.4.3 (NANOFLANN_VERSION 0x142:
/// `SearchParams`, radius results as `std::pair<index, dist²>`); 1.5.0 renamed these to
/// `SearchParameters` and `ResultItem<index, dist²>` (members `.first`/`.second` both ways).
/// Everything else simsr uses (KDTreeSingleIndexAdaptor, L2_Simple_Adaptor, custom result sets
/// with size/full/addPoint/worstDist) is the same in both.

#include <nanoflann.hpp>

#include <cstdint>
#include <utility>

#ifndef NANOFLANN_VERSION
#error "simsr::neighbors needs nanoflann.hpp that defines NANOFLANN_VERSION (nanoflann >= 1.3)"
#endif

namespace simsr::neighbors::compat {

/// Index type of points inside nanoflann trees (both versions default to uint32_t).
using TreeIndex = std::uint32_t;

#if NANOFLANN_VERSION >= 0x150
/// Search options of findNeighbors / radiusSearch.
using SearchParams = nanoflann::SearchParameters;
/// One radius-search hit: `.first` point index, `.second` squared distance.
template <class I, class D>
using RadiusItem = nanoflann::ResultItem<I, D>;
#else
using SearchParams = nanoflann::SearchParams;
template <class I, class D>
using RadiusItem = std::pair<I, D>;
#endif

/// Exact search (eps = 0); `sorted` asks radius results sorted by distance.
inline SearchParams search_params(bool sorted = true) {
  SearchParams p;
  p.eps = 0;
  p.sorted = sorted;
  return p;
}

/// A static L2 kd-tree over `Dataset` (nanoflann's adaptor concept: kdtree_get_point_count,
/// kdtree_get_pt, kdtree_get_bbox) with squared distances in S.
template <class S, class Dataset, int Dim>
using L2Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<S, Dataset, S, TreeIndex>, Dataset, Dim, TreeIndex>;

/// Build parameters (leaf size; newer versions also take flags and build threads, left at defaults).
inline nanoflann::KDTreeSingleIndexAdaptorParams tree_params(std::size_t leaf_max_size) {
  return nanoflann::KDTreeSingleIndexAdaptorParams(leaf_max_size);
}

}  // namespace simsr::neighbors::compat
