#pragma once
/// \file
/// Umbrella of the mesh area: mesh structs, topology, geometry, quality, validation, triangulation.

#include "../core/core.hpp"
#include "closest_point.hpp"
#include "contact_patches.hpp"
#include "cotangent_laplacian.hpp"
#include "harmonic_field.hpp"
#include "normals.hpp"
#include "poly_mesh.hpp"
#include "isosurface.hpp"
#include "loop_subdivision.hpp"
#include "quality.hpp"
#include "rigid_motion.hpp"
#include "tet_overlap.hpp"
#include "tet_mesh.hpp"
#include "topology.hpp"
#include "tri_mesh.hpp"
#include "triangle_intersection.hpp"
#include "triangulate.hpp"
#include "validate.hpp"
#include "vertex_areas.hpp"
#include "volume.hpp"
