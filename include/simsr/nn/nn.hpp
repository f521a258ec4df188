#pragma once
/// \file
/// Umbrella of the nn area: activation layout, parameter store, the Layer concept, the layers,
/// losses, Adam, the composed network, its training and model file, the β-VAE (SPEC §7). Layout
/// and contracts: tensor.hpp and layer.hpp.

#include "activations.hpp"
#include "adam.hpp"
#include "batch_norm.hpp"
#include "beta_vae.hpp"
#include "concat.hpp"
#include "coordinate_upsampling.hpp"
#include "dropout.hpp"
#include "edge_conv.hpp"
#include "face_normal_loss.hpp"
#include "feature_embedding.hpp"
#include "graph_features.hpp"
#include "latent_norm_loss.hpp"
#include "layer.hpp"
#include "linear.hpp"
#include "losses.hpp"
#include "mlp.hpp"
#include "model_file.hpp"
#include "neighbor_upsample.hpp"
#include "network_config.hpp"
#include "normalization.hpp"
#include "parameters.hpp"
#include "pooling.hpp"
#include "positional_encoding.hpp"
#include "siren_decoder.hpp"
#include "super_resolution_loss.hpp"
#include "super_resolution_net.hpp"
#include "tensor.hpp"
#include "trainer.hpp"
