#pragma once
/// \file
/// Two patches of one triangulated surface that must not pass through each other — the upper and
/// the lower lip of the face's skin. The training loss's contact term reads them
/// (nn/contact_loss.hpp), and the evaluation counts the predicted surfaces' intersecting
/// triangle pairs between them (mesh/triangle_intersection.hpp).
///
///     ContactPatches lips{upper, lower};           // rows index the surface's vertices
///     lips.check(surface.num_vertices(), "lips");  // ArgumentError naming the bad row
///     auto pairs = intersecting_triangle_pairs(X, lips.a, lips.b);

#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/fingerprint.hpp"
#include "../core/types.hpp"

namespace simsr {

struct ContactPatches {
  Tris a, b;  ///< triangles of the surface (corners in its outward order), one patch each

  bool empty() const { return a.rows() == 0 || b.rows() == 0; }
  /// Of the triangles: a checkpoint trained with other patches is refused by it.
  std::string fingerprint() const { return Fingerprint().add(a).add(b).hex(); }

  /// ArgumentError, naming `what`, the patch and the row, unless both patches have triangles, every
  /// index lies in [0, num_vertices) and no vertex belongs to both. Returns each vertex's patch:
  /// 1 (a), 2 (b) or 0 (neither).
  std::vector<char> check(Index num_vertices, const std::string& what) const {
    if (empty()) throw ArgumentError(what + ": both contact patches need at least one triangle (a: " + std::to_string(a.rows()) + ", b: " +
                                     std::to_string(b.rows()) + ")");
    std::vector<char> side(std::size_t(num_vertices), 0);
    const Tris* sets[2] = {&a, &b};
    for (int s = 0; s < 2; ++s)
      for (Index t = 0; t < sets[s]->rows(); ++t)
        for (Index k = 0; k < 3; ++k) {
          const VIndex v = (*sets[s])(t, k);
          if (v < 0 || Index(v) >= num_vertices)
            throw ArgumentError(what + ": patch " + (s ? "b" : "a") + " triangle " + std::to_string(t) + " has vertex " + std::to_string(v) +
                                " outside [0, " + std::to_string(num_vertices) + ")");
          char& mark = side[std::size_t(v)];
          if (mark && mark != s + 1) throw ArgumentError(what + ": vertex " + std::to_string(v) + " belongs to both contact patches");
          mark = char(s + 1);
        }
    return side;
  }
};

}  // namespace simsr
