#pragma once
/// \file
/// Umbrella of the physics area (SPEC §3; Park et al. 2023 §4): materials (Teran muscle,
/// Mooney–Rivlin, neo-Hookean, corotated), forces and constraints (track and point springs,
/// bones, gravity, obstacle and self contact), the elastic energy over a tet mesh, the Newton
/// quasistatic solver with its linear-solver policies, and the cantilever verification; SoftDECA's
/// energies (strain band, volume target, bending, targets and distances, implicit dynamics) and
/// the local–global (projective dynamics) solver over the same terms.

#include "dirichlet_boundary.hpp"
#include "elastic_energy.hpp"
#include "energy_term.hpp"
#include "forces/forces.hpp"
#include "hessian.hpp"
#include "linear_solvers/linear_solvers.hpp"
#include "local_global.hpp"
#include "materials/materials.hpp"
#include "quasistatic.hpp"
#include "tet_elements.hpp"
#include "verification/cantilever.hpp"
