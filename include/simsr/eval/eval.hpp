#pragma once
/// \file
/// Umbrella of the eval area: error statistics and the files that report them.
#include "error_statistics.hpp"
#include "intersections.hpp"
#include "report.hpp"
