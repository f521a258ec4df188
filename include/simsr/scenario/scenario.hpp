#pragma once
/// \file
/// The scenario area: simulated data sets built from real input — the face of the core paper (§4)
/// from the ICT FaceKit (the kit and its parts, the jaw hinge read from data), and SoftDECA's
/// layered head, its parameter sampler and its simulation.

#include "face/head_surface.hpp"
#include "face/ict_kit.hpp"
#include "face/jaw.hpp"
#include "face/face_datagen.hpp"
#include "face/face_dataset.hpp"
#include "face/face_lr_source.hpp"
#include "face/face_model.hpp"
#include "face/face_simulator.hpp"
#include "face/face_views.hpp"
#include "face/jaw_weights.hpp"
#include "face/muscles.hpp"
#include "face/performances.hpp"
#include "face/skull.hpp"
#include "face/unseen_forces.hpp"
#include "softdeca/ict_template.hpp"
#include "softdeca/layered_head.hpp"
#include "softdeca/parameters.hpp"
#include "softdeca/softdeca_datagen.hpp"
#include "softdeca/softdeca_dataset.hpp"
#include "softdeca/softdeca_simulator.hpp"
#include "softdeca/sphere_template.hpp"
#include "softdeca/template.hpp"
