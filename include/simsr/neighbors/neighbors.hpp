#pragma once
/// \file
/// Umbrella of the neighbours area: kNN result, NeighborSearch concept, nanoflann kd-tree,
/// brute-force feature kNN and geodesic kNN on mesh edges.

#include "brute_force_knn.hpp"
#include "concepts.hpp"
#include "geodesic_knn.hpp"
#include "kd_tree.hpp"
#include "knn_result.hpp"
#include "nanoflann_compat.hpp"
