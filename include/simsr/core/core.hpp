#pragma once
/// \file
/// Umbrella of the core area: aliases, errors, execution policies and parallel primitives, and
/// Eigen kept single-threaded.

#include "eigen_threads.hpp"
#include "error.hpp"
#include "host_device.hpp"
#include "parallel.hpp"
#include "packed_gemm.hpp"
#include "serial_gemm.hpp"
#include "types.hpp"
#include "work_shard.hpp"
