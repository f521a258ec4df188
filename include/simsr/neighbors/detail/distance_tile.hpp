#pragma once
/// \file
/// The fused distance-and-select kernel of BruteForceKnn's self queries: MR rows × NR columns of
/// approximate squared distances ‖a‖² + ‖b‖² − 2a·b computed in SIMD registers and filtered
/// there against the rows' and the columns' current k-th candidates; only the few entries that
/// can enter a candidate list leave the registers (a callback offers them).
///
/// Why fused: the blocked-GEMM route writes every tile product to memory (a T×T block per tile
/// pair), reads it back to form the distances, and the GEMM library zeroes and packs its
/// operands per call; at the network's feature widths (64) the dot products are short (64 FMAs
/// per entry), so that traffic costs as much as the products. Here the points are packed once per
/// query (panels of NR columns, depth-major), a tile pair streams them through registers, and
/// nothing of size T×T is ever stored.
///
/// Portable SIMD: Eigen's packet primitives (the widest packet the compiler targets: AVX-512's
/// 16 floats under -march=native, SSE's 4 otherwise), so the same source is exact on every target.
/// Arithmetic of one entry: the dot product accumulated over the feature columns in order with
/// pmadd (a fused multiply-add where the target has one), then (‖a‖² + ‖b‖²) − 2·dot. Each entry's
/// value depends only on its two rows, never on the tile, the worker or the thread count, and
/// (a, b) and (b, a) round the same (the products commute, the norms are added in one order),
/// which the symmetric self queries rely on.

#include <Eigen/Core>
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include "../../core/types.hpp"

namespace simsr::neighbors::detail {

/// Register blocking for scalar S on the compiled-for target.
template <class S>
struct DistanceTile {
  using Packet = typename Eigen::internal::packet_traits<S>::type;
  static constexpr int P = Eigen::internal::unpacket_traits<Packet>::size;  ///< lanes per packet
  static constexpr int NR = 2 * P;                                            ///< columns per micro-tile (a panel)
  /// Rows per micro-tile: 2·MR accumulators plus two column packets and a broadcast must fit the
  /// vector registers (32 with AVX-512, 16 with SSE/AVX). MR divides NR, so a micro-tile's rows
  /// lie in one panel and are read from the same packed copy as the columns: one pointer, fixed
  /// offsets (row pointers of their own spilled to the stack: 25 % slower).
  static constexpr int MR = P * int(sizeof(S)) >= 64 ? 8 : std::min(4, NR);
  static_assert(NR % MR == 0);

  /// Packs rows [0, n) of the row-major n×D matrix X into panels of NR rows, depth-major: entry
  /// (p, d) at out[(p / NR)·NR·D + d·NR + p % NR]; the rows past n pad with zeros. Their norms
  /// go to `norms` padded with NaN (a NaN distance passes no filter).
  static void pack(const S* X, Index n, Index D, const S* row_norms, std::vector<S>& out, std::vector<S>& norms) {
    const Index padded = (n + NR - 1) / NR * NR;
    out.assign(static_cast<std::size_t>(padded * D), S(0));
    norms.assign(static_cast<std::size_t>(padded), std::numeric_limits<S>::quiet_NaN());
    for (Index p = 0; p < n; ++p) {
      S* panel = out.data() + (p / NR) * NR * D + p % NR;
      for (Index d = 0; d < D; ++d) panel[d * NR] = X[p * D + d];
      norms[static_cast<std::size_t>(p)] = row_norms[p];
    }
  }

  /// One micro-tile: MR packed rows at `rows` (row r, feature d at rows[d·NR + r]: a slice of a
  /// panel) against the NR packed columns at `panel`. qn: the rows' squared norms (mr of them),
  /// pn: the columns' (NR, NaN-padded). offer(r, l, d2) is called for every entry (r, l) with
  /// d2 ≤ wrow[r] or, with `both`, d2 ≤ wcol[l] (the rows' and columns' thresholds), and
  /// possibly a few more: offer re-checks against the live thresholds. Rows r ≥ mr are computed
  /// (padding) and ignored.
  template <class Offer>
  static void run(const S* rows, const S* panel, Index D, const S* qn, const S* pn, const S* wrow, const S* wcol, int mr, bool both,
                  Offer&& offer) {
    using namespace Eigen::internal;
    Packet acc[MR][2];
    for (int r = 0; r < MR; ++r) acc[r][0] = acc[r][1] = pset1<Packet>(S(0));
    for (Index d = 0; d < D; ++d) {
      const Packet b0 = ploadu<Packet>(panel + d * NR), b1 = ploadu<Packet>(panel + d * NR + P);
      const S* a = rows + d * NR;
#pragma GCC unroll 16
      for (int r = 0; r < MR; ++r) {
        const Packet ar = pset1<Packet>(a[r]);
        acc[r][0] = pmadd(ar, b0, acc[r][0]);
        acc[r][1] = pmadd(ar, b1, acc[r][1]);
      }
    }
    // The thresholds only decrease (offer lowers them), so values read once per micro-tile filter
    // conservatively; offer re-checks against the live ones.
    const Packet n0 = ploadu<Packet>(pn), n1 = ploadu<Packet>(pn + P);
    const Packet wc0 = ploadu<Packet>(wcol), wc1 = ploadu<Packet>(wcol + P);
    alignas(64) S lanes[NR];
#pragma GCC unroll 16
    for (int r = 0; r < MR; ++r) {  // unrolled: the accumulators stay in registers
      if (r >= mr) break;
      const Packet q = pset1<Packet>(qn[r]);
      const Packet d0 = psub(padd(q, n0), padd(acc[r][0], acc[r][0]));
      const Packet d1 = psub(padd(q, n1), padd(acc[r][1], acc[r][1]));
      const Packet w = pset1<Packet>(wrow[r]);
      std::uint64_t bits = le_bits(d0, w) | le_bits(d1, w) << P;
      if (both) bits |= le_bits(d0, wc0) | le_bits(d1, wc1) << P;
      if (!bits) continue;
      pstoreu(lanes, d0);
      pstoreu(lanes + P, d1);
      for (; bits; bits &= bits - 1) {
        const int l = std::countr_zero(bits);
        offer(r, l, lanes[l]);
      }
    }
  }

 private:
  /// Bit l set where lane l of a is ≤ lane l of b (false for NaN).
  static std::uint64_t le_bits(const Packet& a, const Packet& b) {
    // dispatched on the packet's width (std::is_same on the vector types drops their attributes)
    constexpr bool f = std::is_same_v<S, float>;
    constexpr std::size_t bytes = sizeof(Packet);
#if defined(EIGEN_VECTORIZE_AVX512)
    if constexpr (bytes == 64 && f)
      return _mm512_cmp_ps_mask(a, b, _CMP_LE_OQ);
    else if constexpr (bytes == 64)
      return _mm512_cmp_pd_mask(a, b, _CMP_LE_OQ);
    else
#endif
#if defined(EIGEN_VECTORIZE_AVX)
    if constexpr (bytes == 32 && f)
      return static_cast<std::uint32_t>(_mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_LE_OQ)));
    else if constexpr (bytes == 32)
      return static_cast<std::uint32_t>(_mm256_movemask_pd(_mm256_cmp_pd(a, b, _CMP_LE_OQ)));
    else
#endif
#if defined(EIGEN_VECTORIZE_SSE2)
    if constexpr (bytes == 16 && f)
      return static_cast<std::uint32_t>(_mm_movemask_ps(_mm_cmple_ps(a, b)));
    else if constexpr (bytes == 16)
      return static_cast<std::uint32_t>(_mm_movemask_pd(_mm_cmple_pd(a, b)));
    else
#endif
    {  // any other target (a scalar "packet" included): lane by lane
      S va[P], vb[P];
      Eigen::internal::pstoreu(va, a);
      Eigen::internal::pstoreu(vb, b);
      std::uint64_t bits = 0;
      for (int l = 0; l < P; ++l) bits |= std::uint64_t(va[l] <= vb[l]) << l;
      return bits;
    }
  }
};

}  // namespace simsr::neighbors::detail
