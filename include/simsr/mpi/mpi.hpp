#pragma once
/// \file
/// simsr::mpi's umbrella (optional: `-DSIMSR_WITH_MPI=ON`, target `simsr::mpi`): the communicator
/// and what runs over ranks (SoftDECA's datagen by sample, the face's by performance, data-parallel training). Not included by simsr/simsr.hpp,
/// which needs no MPI.

#include "batch_group.hpp"
#include "communicator.hpp"
#include "face_datagen.hpp"
#include "softdeca_datagen.hpp"
