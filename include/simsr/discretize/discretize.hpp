#pragma once
/// \file
/// Umbrella of the discretize area: voxelization, cell splits, the BCC embedded lattice and the
/// barycentric embedding of surfaces in tet meshes (Park et al. 2023, §4).

#include "../mesh/generators.hpp"
#include "bcc_lattice.hpp"
#include "cell_split.hpp"
#include "embedding.hpp"
#include "material_split.hpp"
#include "voxelize.hpp"
