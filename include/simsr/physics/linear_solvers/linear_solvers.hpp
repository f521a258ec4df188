#pragma once
/// \file
/// Umbrella of the Newton linear solvers: the concept, PCG (Jacobi, block-Jacobi, incomplete
/// Cholesky, multigrid) and sparse Cholesky.

#include "conjugate_gradient.hpp"
#include "incomplete_cholesky.hpp"
#include "linear_solver.hpp"
#include "multigrid.hpp"
#include "sparse_cholesky.hpp"
