#pragma once
/// \file
/// Forces and constraints of the quasistatic soft-tissue solver (SPEC §3): track and point
/// springs, gravity, bone attachments (Dirichlet constraints), obstacle and self-contact; and
/// SoftDECA's surface terms (bending, target and distance attraction) and its dynamics; the
/// cloth membrane (TriangleMembrane).

#include "bone_attachment.hpp"
#include "embedded_springs.hpp"
#include "gravity.hpp"
#include "implicit_inertia.hpp"
#include "obstacle_contact.hpp"
#include "obstacle_shapes.hpp"
#include "self_contact.hpp"
#include "surface_bending.hpp"
#include "triangle_membrane.hpp"
#include "vertex_forces.hpp"
#include "vertex_targets.hpp"
