#pragma once
/// \file
/// Umbrella header: every area of simsr, in the order data flows through them
/// (core → mesh/io → discretize → physics → neighbors → data → scenario | nn → interp | shell → eval →
/// pipeline).
/// Include single areas (simsr/mesh/mesh.hpp, simsr/interp/interp.hpp, ...) to keep compile
/// times short. simsr/mpi/mpi.hpp is not among them: it needs MPI (the optional simsr::mpi).

#include "core/core.hpp"
#include "data/data.hpp"
#include "discretize/discretize.hpp"
#include "eval/eval.hpp"
#include "interp/interp.hpp"
#include "io/io.hpp"
#include "mesh/mesh.hpp"
#include "neighbors/neighbors.hpp"
#include "nn/nn.hpp"
#include "physics/physics.hpp"
#include "pipeline/pipeline.hpp"
#include "scenario/scenario.hpp"
#include "shell/shell.hpp"
