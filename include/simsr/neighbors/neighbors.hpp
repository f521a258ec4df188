#pragma once
/// \file
/// Umbrella of the neighbours area: kNN result, NeighborSearch concept, nanoflann kd-tree, 3-D grid kNN,
/// brute-force feature kNN, geodesic kNN on mesh edges, LR→HR linear assignment and the
/// upsampling neighbourhoods built on it.

#include "brute_force_knn.hpp"
#include "concepts.hpp"
#include "geodesic_knn.hpp"
#include "grid_knn.hpp"
#include "kd_tree.hpp"
#include "knn_result.hpp"
#include "linear_assignment.hpp"
#include "nanoflann_compat.hpp"
#include "point_assignment.hpp"
#include "sparse_assignment.hpp"
#include "surface_distance.hpp"
#include "surface_graph.hpp"
#include "upsampling_neighborhoods.hpp"
