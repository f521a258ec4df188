#pragma once
/// \file
/// Umbrella of the nn area: activation layout, parameter store, the Layer concept, the layers,
/// losses and Adam (SPEC §7). Layout and contracts: tensor.hpp and layer.hpp.

#include "activations.hpp"
#include "adam.hpp"
#include "batch_norm.hpp"
#include "beta_vae.hpp"
#include "concat.hpp"
#include "dropout.hpp"
#include "edge_conv.hpp"
#include "face_normal_loss.hpp"
#include "graph_features.hpp"
#include "latent_norm_loss.hpp"
#include "layer.hpp"
#include "linear.hpp"
#include "losses.hpp"
#include "neighbor_upsample.hpp"
#include "parameters.hpp"
#include "pooling.hpp"
#include "positional_encoding.hpp"
#include "tensor.hpp"
