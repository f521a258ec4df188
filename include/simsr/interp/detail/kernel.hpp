#pragma once
/// \file
/// Pieces shared by the interpolators of interp/: the Gaussian kernel of A.2/A.3, the mean edge
/// length that scales default kernel widths, shape checks of `apply`, and the sparse M×k gather
/// Δx^H_j = Σ_n w_jn ΔX^L_{i(j,n)} that IDW and MLS reduce to once fitted (Eq. 1's form).

#include <cmath>
#include <string>

#include "../../core/device_buffer.hpp"
#include "../../core/error.hpp"
#include "../../core/host_device.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../../mesh/topology.hpp"

namespace simsr::interp::detail {

/// φ(R) = exp(−R²/σ²) (Eq. 9 and 14), R and σ in the units of the positions.
inline double gaussian(double r, double sigma) { return std::exp(-(r * r) / (sigma * sigma)); }

/// Mean Euclidean length of the unique edges of elements E (#E×2..4) over vertices V (#V×3).
/// ArgumentError when E has no edge (no element), since no length scale can be derived then.
template <class DV, class DE>
double mean_edge_length(const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DE>& E, const std::string& who) {
  const Edges U = unique_edges(E);
  if (U.rows() == 0) throw ArgumentError(who + ": the LR mesh has no edges, so no default kernel width; set sigma explicitly");
  double sum = 0;
  for (Index e = 0; e < U.rows(); ++e)
    sum += (V.row(U(e, 0)).template cast<double>() - V.row(U(e, 1)).template cast<double>()).norm();
  return sum / double(U.rows());
}

/// ShapeError unless lr is N×3 and hr is M×3 (`apply` never resizes the caller's buffer).
template <class LR, class HR>
void check_apply_shapes(const std::string& who, Index n, Index m, const LR& lr, const HR& hr) {
  if (lr.rows() != n) throw ShapeError(who + ": lr_displacement", {n, 3}, {lr.rows(), lr.cols()});
  if (hr.rows() != m) throw ShapeError(who + ": hr_displacement", {m, 3}, {hr.rows(), hr.cols()});
}

/// NeighborGather's body, one HR row j (all three components): hr(j, ·) = Σ_n w_jn lr(i(j, n), ·),
/// the sum over n ascending. SIMSR_HOST_DEVICE over raw arrays: NeighborGather::apply runs it
/// under seq and omp, DeviceNeighborGather (IDW's and MLS's device twin) under exec::cuda.
template <class S>
struct NeighborGatherRow {
  const VIndex* indices;  ///< M×k row-major
  const S* weights;       ///< M×k, or M×3k when per_component
  Index k;
  bool per_component;
  MatrixSpan<const S> lr;  ///< N×3
  MatrixSpan<S> hr;        ///< M×3

  SIMSR_HOST_DEVICE void operator()(Index j) const {
    const VIndex* ij = indices + j * k;
    if (per_component) {
      const S* wj = weights + j * 3 * k;
      for (int c = 0; c < 3; ++c) {
        S acc = 0;
        for (Index n = 0; n < k; ++n) acc += wj[c * k + n] * lr(Index(ij[n]), c);
        hr(j, c) = acc;
      }
    } else {
      const S* wj = weights + j * k;
      S a0 = 0, a1 = 0, a2 = 0;
      for (Index n = 0; n < k; ++n) {
        const S* xi = lr.data + Index(ij[n]) * lr.stride;
        a0 += wj[n] * xi[0];
        a1 += wj[n] * xi[1];
        a2 += wj[n] * xi[2];
      }
      hr(j, 0) = a0;
      hr(j, 1) = a1;
      hr(j, 2) = a2;
    }
  }
};

/// The device twins' check of apply's arrays: lr N×3 and hr M×3 (ShapeError naming `who`).
template <class S>
void check_apply_spans(const std::string& who, Index n, Index m, const MatrixSpan<const S>& lr, const MatrixSpan<S>& hr) {
  if (lr.rows != n || lr.cols != 3) throw ShapeError(who + ": LR displacement", {n, 3}, {lr.rows, lr.cols});
  if (hr.rows != m || hr.cols != 3) throw ShapeError(who + ": HR displacement", {m, 3}, {hr.rows, hr.cols});
}

/// A dense M×N operator's row j applied to the three components: hr(j, ·) = Σ_i A(j, i) lr(i, ·),
/// the sum over i ascending (RBF's precomputed operator). SIMSR_HOST_DEVICE over raw arrays: RBF's
/// apply runs it under seq and omp, DeviceRbf under exec::cuda.
template <class S>
struct DenseOperatorRow {
  const S* op;  ///< M×N row-major
  Index n;
  MatrixSpan<const S> lr;  ///< N×3
  MatrixSpan<S> hr;        ///< M×3

  SIMSR_HOST_DEVICE void operator()(Index j) const {
    const S* aj = op + j * n;
    S a0 = 0, a1 = 0, a2 = 0;
    for (Index i = 0; i < n; ++i) {
      const S* xi = lr.data + i * lr.stride;
      a0 += aj[i] * xi[0];
      a1 += aj[i] * xi[1];
      a2 += aj[i] * xi[2];
    }
    hr(j, 0) = a0, hr(j, 1) = a1, hr(j, 2) = a2;
  }
};

/// A fitted linear map LR → HR displacements with k LR vertices per HR row.
/// `indices` M×k LR ids; `weights` M×k (one weight per neighbour for all three components) or
/// M×3k (per component c, entries [c·k, c·k + k)). Each row is computed alone, in neighbour
/// order, so every policy gives the same bits.
template <class S>
struct NeighborGather {
  Eigen::Matrix<VIndex, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> indices;
  Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> weights;
  bool per_component = false;

  Index rows() const { return indices.rows(); }
  Index k() const { return indices.cols(); }

  /// hr.row(j) = Σ_n weights(j, ·n) lr.row(indices(j, n)); hr must already be M×3.
  template <exec::HostPolicy Policy>
  void apply(Policy policy, const ConstPointsRef<S>& lr, PointsRef<S> hr) const {
    exec::parallel_for(policy, rows(),
                       NeighborGatherRow<S>{indices.data(), weights.data(), k(), per_component, {lr.data(), lr.rows(), 3, lr.outerStride()},
                                            {hr.data(), hr.rows(), 3, hr.outerStride()}});
  }
};

/// The first k columns of the problem's neighbourhoods (ids and geodesic distances), checked.
template <class Problem>
const auto& neighborhoods_for(const Problem& problem, Index k, const std::string& who) {
  if (k < 1) throw ArgumentError(who + ": k = " + std::to_string(k) + " must be ≥ 1");
  if (!problem.neighborhoods)
    throw ArgumentError(who + ": the upsampling problem has no neighbourhoods; call problem.ensure_neighborhoods(" +
                        std::to_string(k) + ") or load saved ones first");
  return problem.checked_neighborhoods(k);
}

}  // namespace simsr::interp::detail
