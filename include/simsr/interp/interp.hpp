#pragma once
/// \file
/// Umbrella of interp/: LR volume displacements → HR surface displacements (SPEC §6), every
/// method an `interp::Interpolator` (fit once on rest shapes, apply per frame).
///  - Embedded: barycentric embedding of the HR surface in the LR tets (the paper's baseline);
///  - IDW: inverse distance weights over the §3.2 neighbourhoods;
///  - RBF: global Gaussian RBF (appendix A.2, Eq. 8–11), geodesic or Euclidean distances;
///  - MLS: moving least squares (appendix A.3, Eq. 12–16), as written or 3-D linear;
///  - Ridge: ridge regression over a base interpolator, trained on paired frames (SPEC §6);
///  - BetaVaeBaseline: the β-VAE of appendix A.4, trained on paired frames;
///  - Learned: the super-resolution network of §3, trained on paired frames.
/// Ridge, BetaVaeBaseline and Learned are `TrainableInterpolator`s; `needs_neighborhoods_v<I>`
/// says which methods read the §3.2 neighbourhoods.

#include "apply_frames.hpp"
#include "by_name.hpp"
#include "beta_vae.hpp"
#include "concepts.hpp"
#include "embedded.hpp"
#include "fit_and_train.hpp"
#include "idw.hpp"
#include "learned.hpp"
#include "local_linear.hpp"
#include "network_recipe.hpp"
#include "mls.hpp"
#include "problem.hpp"
#include "rbf.hpp"
#include "ridge.hpp"
