#pragma once
/// \file
/// The data area: what a super-resolution experiment reads and splits before any method runs —
/// rest shapes from mesh files, paired LR/HR frame sets (positions or displacements, ids,
/// controls, sequences), train/test splits (every n-th frame, or whole sequences), and the
/// network's neighbourhoods from the authors' files, simsr's own, or computed.

#include "concatenate.hpp"
#include "contact_patches_file.hpp"
#include "frame_set.hpp"
#include "network_neighborhoods.hpp"
#include "paired_frames.hpp"
#include "rest_shapes.hpp"
#include "splits.hpp"
