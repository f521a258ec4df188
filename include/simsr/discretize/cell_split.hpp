#pragma once
/// \file
/// How a kept voxel is cut into tets: policies for build_lattice (bcc_lattice.hpp), chosen by
/// one type: `build_lattice<BccSplit>(cells)` vs `build_lattice<FreudenthalSplit>(cells)`.
///
/// Lattice nodes are named by *doubled* integer coordinates N: the node sits at
/// grid.origin + (h/2)·N; cube corners have even N, cube centres odd N. A policy's
/// `split(cell, emit)` calls `emit(std::array<NodeCoord, 4>, other_cell)` per tet, where
/// other_cell is the index of a second kept cell the tet overlaps (−1 if none); orientation is
/// fixed afterwards from the exact integer determinant.
///
/// Mean ratio (quality.hpp, 1 = regular) of the tets each split makes, min / mean over a 6³ box:
///
/// | policy                 | nodes           | tets per cell              | conforming | mean ratio    |
/// |------------------------|-----------------|----------------------------|------------|---------------|
/// | BccSplit (default)     | corners+centres | 12 (interior), see below   | yes        | 0.762 / 0.921 |
/// | FreudenthalSplit       | corners         | 6 Kuhn simplices           | yes        | 0.756 / 0.756 |
/// | AlternatingSplit       | corners         | 5, parity-alternating      | yes        | 0.840 / 0.872 |
/// | CentredFiveSplit<alt>  | corners+centres | 8: 4 corner + 4 centre     | alt only   | 0.577 / 0.709 |
///
/// CentredFiveSplit<false> is the split of the authors' bunny LR mesh (lrestshape.obj): the same
/// 5-tet split in every cell with its regular central tet cut into 4 at the cube centre; the face
/// diagonals of neighbouring cells cross, so that mesh shares vertices but not faces.

#include <array>
#include <cstdint>

#include "../core/types.hpp"
#include "../mesh/generators.hpp"

namespace simsr::discretize {

/// Doubled integer lattice coordinates of a node (see the file comment).
using NodeCoord = std::array<std::int64_t, 3>;

/// What a split policy sees of one kept cell.
template <class Neighbour>
struct CellContext {
  std::array<Index, 3> ijk;  ///< grid cell
  Index index;               ///< index among the kept cells
  Neighbour neighbour;       ///< neighbour(axis, dir ∈ {−1, +1}) → kept-cell index or −1

  NodeCoord corner(int b) const {
    return {2 * (ijk[0] + (b & 1)), 2 * (ijk[1] + ((b >> 1) & 1)), 2 * (ijk[2] + ((b >> 2) & 1))};
  }
  NodeCoord centre() const { return {2 * ijk[0] + 1, 2 * ijk[1] + 1, 2 * ijk[2] + 1}; }
};

/// Body-centred cubic lattice (Molino et al. 2003): nodes at cube corners and cube centres. Each
/// face shared by two kept cells carries 4 tets (centre_a, centre_b, face edge), every one
/// straddling the face (half its volume, h³/24, in each cell); 12 per cell in the interior.
/// A face on the boundary of the kept set gets a pyramid (own centre + face square) cut into 2 tets
/// along the face diagonal through the square's lowest corner, so the lattice covers exactly the
/// union of kept cells (h³/6 per face either way) and its boundary is the cells' outer faces.
/// Mean ratio 0.952 for face tets (edges h, h, 4×(√3/2)h), 0.762 for the pyramid halves.
struct BccSplit {
  static constexpr bool uses_centres = true;
  template <class Ctx, class Emit>
  static void split(const Ctx& cell, Emit&& emit) {
    for (int a = 0; a < 3; ++a)
      for (int dir : {-1, 1}) {
        const Index nb = cell.neighbour(a, dir);
        if (nb >= 0 && dir < 0) continue;  // that face's tets are emitted by the lower cell
        const int u = (a + 1) % 3, v = (a + 2) % 3;
        const int side = dir > 0 ? (1 << a) : 0;
        const int q[4] = {side, side | (1 << u), side | (1 << u) | (1 << v), side | (1 << v)};  // square, cyclic
        const NodeCoord c = cell.centre();
        if (nb >= 0) {
          NodeCoord c2 = c;
          c2[a] += 2;
          for (int e = 0; e < 4; ++e) emit(std::array<NodeCoord, 4>{c, c2, cell.corner(q[e]), cell.corner(q[(e + 1) % 4])}, nb);
        } else {
          emit(std::array<NodeCoord, 4>{c, cell.corner(q[0]), cell.corner(q[1]), cell.corner(q[2])}, Index(-1));
          emit(std::array<NodeCoord, 4>{c, cell.corner(q[0]), cell.corner(q[2]), cell.corner(q[3])}, Index(-1));
        }
      }
  }
};

/// Freudenthal (Kuhn) split: 6 tets around each cube's main diagonal, the same in every cell, so
/// any two neighbours conform. Corners only.
struct FreudenthalSplit {
  static constexpr bool uses_centres = false;
  template <class Ctx, class Emit>
  static void split(const Ctx& cell, Emit&& emit) {
    for (const auto& t : simsr::detail::kuhn_tets)
      emit(std::array<NodeCoord, 4>{cell.corner(t[0]), cell.corner(t[1]), cell.corner(t[2]), cell.corner(t[3])}, Index(-1));
  }
};

/// 5-tet split, central tet on the even corners where i+j+k is even and on the odd ones
/// elsewhere: neighbouring cells then carry the same face diagonal. Corners only.
struct AlternatingSplit {
  static constexpr bool uses_centres = false;
  template <class Ctx, class Emit>
  static void split(const Ctx& cell, Emit&& emit) {
    const auto& table = (cell.ijk[0] + cell.ijk[1] + cell.ijk[2]) % 2 == 0 ? simsr::detail::five_tets_even : simsr::detail::five_tets_odd;
    for (const auto& t : table)
      emit(std::array<NodeCoord, 4>{cell.corner(t[0]), cell.corner(t[1]), cell.corner(t[2]), cell.corner(t[3])}, Index(-1));
  }
};

/// 5-tet split whose regular central tet is cut into 4 at the cube centre: 4 corner tets (h³/6)
/// and 4 centre tets (h³/12). `Alternate` = true alternates with parity as AlternatingSplit
/// (conforming); false uses the odd central tet {1, 2, 4, 7} everywhere, as the bunny LR mesh
/// does (not conforming: neighbouring face diagonals cross).
template <bool Alternate = true>
struct CentredFiveSplit {
  static constexpr bool uses_centres = true;
  template <class Ctx, class Emit>
  static void split(const Ctx& cell, Emit&& emit) {
    const bool even = Alternate && (cell.ijk[0] + cell.ijk[1] + cell.ijk[2]) % 2 == 0;
    const auto& table = even ? simsr::detail::five_tets_even : simsr::detail::five_tets_odd;
    for (int t = 1; t < 5; ++t)
      emit(std::array<NodeCoord, 4>{cell.corner(table[t][0]), cell.corner(table[t][1]), cell.corner(table[t][2]),
                                    cell.corner(table[t][3])},
           Index(-1));
    const auto& core = table[0];
    for (int f = 0; f < 4; ++f)
      emit(std::array<NodeCoord, 4>{cell.centre(), cell.corner(core[(f + 1) % 4]), cell.corner(core[(f + 2) % 4]),
                                    cell.corner(core[(f + 3) % 4])},
           Index(-1));
  }
};

/// Satisfied by the split policies above (and any type with the same shape).
template <class P>
concept CellSplit = requires {
  { P::uses_centres } -> std::convertible_to<bool>;
};

}  // namespace simsr::discretize
