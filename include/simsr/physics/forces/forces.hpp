#pragma once
/// \file
/// Forces and constraints of the quasistatic soft-tissue solver (SPEC §3): track and point
/// springs, gravity, bone attachments (Dirichlet constraints), obstacle and self-contact.

#include "bone_attachment.hpp"
#include "embedded_springs.hpp"
#include "gravity.hpp"
#include "obstacle_contact.hpp"
#include "self_contact.hpp"
