#pragma once
/// \file
/// The constitutive models (SPEC §3): the Material concept and every material of simsr.

#include "by_name.hpp"
#include "corotated.hpp"
#include "fibre_curves.hpp"
#include "isotropic.hpp"
#include "material.hpp"
#include "mooney_rivlin.hpp"
#include "neo_hookean.hpp"
#include "signed_svd.hpp"
#include "strain_limit.hpp"
#include "teran_muscle.hpp"
#include "volume_target.hpp"
