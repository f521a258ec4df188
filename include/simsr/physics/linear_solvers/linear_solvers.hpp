#pragma once
/// \file
/// Umbrella of the Newton linear solvers: the concept, PCG (Jacobi, block-Jacobi) and sparse Cholesky.

#include "conjugate_gradient.hpp"
#include "incomplete_cholesky.hpp"
#include "linear_solver.hpp"
#include "sparse_cholesky.hpp"
