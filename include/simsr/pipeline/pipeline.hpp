#pragma once
/// \file
/// Umbrella of pipeline/: long runs as stages a rerun reuses (stages.hpp) and the paper's
/// evaluation end to end on the face or the bunny (demo.hpp, `simsr demo`).

#include "demo.hpp"
#include "stages.hpp"
