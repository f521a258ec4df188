#pragma once
/// \file
/// Thin shells (Chen et al. 2023, "Deep Deformation Detail Synthesis for Thin Shell Models"):
/// TS-ACAP deformation features of triangle-mesh sequences and their inverse map; the mesh
/// encoders and decoders of the network.
///
///     simsr::shell::TsAcap<double> acap(simsr::exec::omp, rest_V, F);   // once per mesh
///     simsr::shell::TsAcapState<double> state;                          // one per sequence
///     auto f = acap.encode(simsr::exec::omp, V_t, state);            // #V×9 per frame
///     auto V = acap.decode(simsr::exec::omp, f, centroid);           // back to positions

#include "deform_transformer.hpp"
#include "mesh_autoencoder.hpp"
#include "one_ring_fit.hpp"
#include "polar_rotation.hpp"
#include "rotation_consistency.hpp"
#include "ts_acap.hpp"
#include "wind.hpp"
#include "cloth_simulator.hpp"
#include "cloth_scenes.hpp"
#include "cloth_datagen.hpp"
#include "collision_refinement.hpp"
#include "cloth_data.hpp"
#include "detail_synthesis.hpp"
#include "cloth_synthesis.hpp"
#include "cloth_upsampling.hpp"
#include "cloth_demo.hpp"
