#pragma once
/// \file
/// Umbrella header: every area of simsr. Include single areas (simsr/core/core.hpp, ...) to keep
/// compile times short.

#include "core/core.hpp"
