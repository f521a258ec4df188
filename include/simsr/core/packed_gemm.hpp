#pragma once
/// \file
/// y = b + x·Wᵀ with the weight W packed once into register panels: the forward products of the
/// network's layers (nn::Linear and the eval paths built on it), where W is small (at most a few
/// hundred square), the same for every row chunk of a forward, and x has many rows.
///
/// Why not SerialGemm (Eigen's packed kernel) here: Eigen packs W again on every call (one per
/// row chunk), zeroes C before it accumulates, and its 48×4 register block reached 39–75 float
/// multiply-adds per ns on one core of this machine (Zen 5, AVX-512) at the layers' chunk shapes
/// (560 rows × in 64…384 × out 32…512; bench_core's BM_LayerProducts_*), the bias added in another
/// pass; this kernel, the register tiling of neighbors::detail::DistanceTile applied to a product,
/// reached 107–113 there, and starts its accumulators from the bias: no zeroing pass, no bias pass.
///
/// Arithmetic of one entry: y(r, o) = init(o) + Σ_d x(r, d)·W(o, d), accumulated over d in order
/// with pmadd (a fused multiply-add where the target has one), init the bias (or 0, or y's own
/// value when accumulating). It depends on the row and W only, never on how the rows are chunked,
/// which worker runs them, or the thread count.
/// Portable SIMD: Eigen's packet primitives (AVX-512's 16 floats under -march=native, SSE's 4
/// otherwise, one scalar lane without SIMD).

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

#include "error.hpp"
#include "types.hpp"

namespace simsr {

template <class S>
class PackedGemm {
 public:
  using Packet = typename Eigen::internal::packet_traits<S>::type;
  static constexpr int P = Eigen::internal::unpacket_traits<Packet>::size;  ///< lanes per packet
  static constexpr int NR = 2 * P;                                            ///< outputs per panel
  /// Rows per micro-tile: 2·MR accumulators, two weight packets and a broadcast in the vector
  /// registers (32 with AVX-512, 16 with SSE/AVX).
  static constexpr int MR = P * int(sizeof(S)) >= 64 ? 8 : 4;

  /// Per-worker scratch of run(): the last rows and the edge tiles.
  struct Workspace {
    std::vector<S> buf;
  };

  /// Packs W (out×in, row-major with leading dimension ldw ≥ in) into panels of NR outputs,
  /// depth-major: W(o, d) at panels[(o / NR)·NR·in + d·NR + o % NR], the outputs past `out`
  /// padded with zeros. Allocates only when the shape grows.
  void pack(const S* W, Index out, Index in, Index ldw) {
    if (out < 0 || in < 0 || ldw < in)
      throw ArgumentError("PackedGemm::pack: out " + std::to_string(out) + ", in " + std::to_string(in) + ", ldw " + std::to_string(ldw) +
                          " (needs out, in >= 0 and ldw >= in)");
    out_ = out, in_ = in;
    const Index np = (out + NR - 1) / NR;
    panels_.resize(static_cast<std::size_t>(np * NR * in));
    for (Index p = 0; p < np; ++p) {
      S* panel = panels_.data() + p * NR * in;
      const Index o0 = p * NR, cols = std::min<Index>(NR, out - o0);
      for (Index d = 0; d < in; ++d) {
        for (Index c = 0; c < cols; ++c) panel[d * NR + c] = W[(o0 + c) * ldw + d];
        for (Index c = cols; c < NR; ++c) panel[d * NR + c] = S(0);
      }
    }
  }
  Index out_features() const { return out_; }
  Index in_features() const { return in_; }

  /// Sizes `ws` for run() with the packed shape (run sizes it itself otherwise, once).
  void reserve(Workspace& ws) const {
    const std::size_t need = workspace_size();
    if (ws.buf.size() < need) ws.buf.resize(need);
  }

  /// y (rows×out, leading dimension ldy ≥ out) = bias + x·Wᵀ, x rows×in (leading dimension
  /// ldx ≥ in), bias `out` values or nullptr (0); with `accumulate`, y += x·Wᵀ (bias ignored).
  void run(Workspace& ws, Index rows, const S* x, Index ldx, const S* bias, S* y, Index ldy, bool accumulate) const {
    if (rows == 0 || out_ == 0) return;
    reserve(ws);
    S* xp = ws.buf.data();       // the last MR rows of x, when fewer remain
    S* yt = xp + MR * in_;       // an edge tile's MR×NR output
    S* init = yt + MR * NR;      // an edge tile's MR×NR starting values
    const Index np = (out_ + NR - 1) / NR;
    for (Index r0 = 0; r0 < rows; r0 += MR) {
      const Index m = std::min<Index>(MR, rows - r0);
      const S* xs = x + r0 * ldx;  // the rows are read in place: MR broadcasts per depth step
      Index lds = ldx;
      if (m < MR) {  // the last rows through a copy whose rows past m repeat the last one (computed, never stored)
        for (Index r = 0; r < MR; ++r) std::copy_n(x + (r0 + std::min<Index>(r, m - 1)) * ldx, in_, xp + r * in_);
        xs = xp, lds = in_;
      }
      for (Index p = 0; p < np; ++p) {
        const Index o0 = p * NR, cols = std::min<Index>(NR, out_ - o0);
        S* yb = y + r0 * ldy + o0;
        const bool full = m == MR && cols == NR;
        const S* start;
        Index ld_start;
        if (accumulate) {
          if (full) {
            start = yb, ld_start = ldy;
          } else {
            std::fill(init, init + MR * NR, S(0));
            for (Index r = 0; r < m; ++r) std::copy_n(yb + r * ldy, cols, init + r * NR);
            start = init, ld_start = NR;
          }
        } else if (bias && cols == NR) {
          start = bias + o0, ld_start = 0;
        } else {
          std::fill(init, init + NR, S(0));
          if (bias) std::copy_n(bias + o0, cols, init);
          start = init, ld_start = 0;
        }
        const S* panel = panels_.data() + p * NR * in_;
        if (full) {
          micro(xs, lds, panel, in_, start, ld_start, yb, ldy);
        } else {
          micro(xs, lds, panel, in_, start, ld_start, yt, NR);
          for (Index r = 0; r < m; ++r) std::copy_n(yt + r * NR, cols, yb + r * ldy);
        }
      }
    }
  }

 private:
  std::size_t workspace_size() const { return static_cast<std::size_t>(MR * in_ + 2 * MR * NR); }

  /// One MR×NR tile: accumulators from `start` (row r at start + r·ld_start; ld_start 0: one row
  /// for all), then the depth loop over the MR rows of x in place (leading dimension ldx), then
  /// stored to y (leading dimension ldy). Packing x too (as DistanceTile packs its rows) measured
  /// slower here: the transposing copy cost more than the strided broadcasts.
  static void micro(const S* x, Index ldx, const S* panel, Index in, const S* start, Index ld_start, S* y, Index ldy) {
    using namespace Eigen::internal;
    Packet acc[MR][2];
#pragma GCC unroll 16
    for (int r = 0; r < MR; ++r) {  // every loop over r unrolled: the accumulators stay in registers
      acc[r][0] = ploadu<Packet>(start + r * ld_start);
      acc[r][1] = ploadu<Packet>(start + r * ld_start + P);
    }
    for (Index d = 0; d < in; ++d) {
      const Packet w0 = ploadu<Packet>(panel + d * NR), w1 = ploadu<Packet>(panel + d * NR + P);
#pragma GCC unroll 16
      for (int r = 0; r < MR; ++r) {
        const Packet a = pset1<Packet>(x[r * ldx + d]);
        acc[r][0] = pmadd(a, w0, acc[r][0]);
        acc[r][1] = pmadd(a, w1, acc[r][1]);
      }
    }
#pragma GCC unroll 16
    for (int r = 0; r < MR; ++r) {
      pstoreu(y + r * ldy, acc[r][0]);
      pstoreu(y + r * ldy + P, acc[r][1]);
    }
  }

  Index out_ = 0, in_ = 0;
  std::vector<S> panels_;
};

}  // namespace simsr
