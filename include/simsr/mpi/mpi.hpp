#pragma once
/// \file
/// simsr::mpi's umbrella (optional: `-DSIMSR_WITH_MPI=ON`, target `simsr::mpi`): the communicator
/// and what runs over ranks (SoftDECA's datagen by sample). Not included by simsr/simsr.hpp,
/// which needs no MPI.

#include "communicator.hpp"
#include "softdeca_datagen.hpp"
