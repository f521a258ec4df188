#pragma once
/// \file
/// Umbrella of pipeline/: long runs as stages a rerun reuses (stages.hpp), the paper's
/// evaluation end to end on the face or the bunny (demo.hpp, `simsr demo`), an LR simulation and
/// an interpolator run live, pipelined (live.hpp), and the face animated that way (animate.hpp,
/// `simsr animate`).

#include "ablations.hpp"
#include "animate.hpp"
#include "demo.hpp"
#include "live.hpp"
#include "stages.hpp"
#include "unseen_views.hpp"
