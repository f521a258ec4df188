#pragma once
/// \file
/// Scalar, index and matrix aliases shared by every area of simsr.

#include <Eigen/Core>
#include <cstdint>

namespace simsr {

/// Default floating-point type of geometry and physics (the paper's data are float64).
using Scalar = double;

/// Sizes and loop counters: Eigen's signed 64-bit index.
using Index = Eigen::Index;

/// Indices as stored in connectivity arrays (#T×4, #F×3, neighbour lists). 32 bits halve the
/// memory traffic of gathers at the paper's 1.9M tets; 2^31 elements is far above any mesh here.
using VIndex = std::int32_t;

/// #V×3 vertex positions, one row per vertex (row-major: a vertex's xyz are contiguous, as in
/// `.npy` frames and nanoflann point clouds).
template <class S = Scalar>
using Points = Eigen::Matrix<S, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// #V×3 positions read in place: a Points, a row block of one, a Map of contiguous row-major
/// memory (a NumPy array through the Python module). Any other layout (column-major, a row stride
/// other than 3) is copied into a temporary by Eigen. What per-frame calls take (interp's
/// `apply`), so that no caller has to copy its frame into a Points first.
template <class S = Scalar>
using ConstPointsRef = Eigen::Ref<const Points<S>, 0, Eigen::OuterStride<3>>;

/// #V×3 positions written in place (contiguous row-major, as ConstPointsRef; never resized: the
/// caller sizes the buffer, and another layout does not compile).
template <class S = Scalar>
using PointsRef = Eigen::Ref<Points<S>, 0, Eigen::OuterStride<3>>;

/// #T×4 tetrahedra (vertex indices).
using Tets = Eigen::Matrix<VIndex, Eigen::Dynamic, 4, Eigen::RowMajor>;

/// #F×3 triangles (vertex indices, counter-clockwise seen from outside).
using Tris = Eigen::Matrix<VIndex, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// #E×2 edges (vertex indices, first < second for unique edge lists).
using Edges = Eigen::Matrix<VIndex, Eigen::Dynamic, 2, Eigen::RowMajor>;

template <class S = Scalar>
using Vec3 = Eigen::Matrix<S, 3, 1>;

template <class S = Scalar>
using Mat3 = Eigen::Matrix<S, 3, 3>;

template <class S = Scalar>
using VecX = Eigen::Matrix<S, Eigen::Dynamic, 1>;

using IndexVector = Eigen::Matrix<VIndex, Eigen::Dynamic, 1>;

}  // namespace simsr
