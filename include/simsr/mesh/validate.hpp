#pragma once
/// \file
/// Mesh validation: `check` counts every problem of a TetMesh/TriMesh and remembers the first
/// offending vertex or element of each kind; `validate` throws MeshError naming the first one.
///
///     simsr::validate(exec::omp, mesh);                  // throws "tet 17: inverted (volume -0.002)"
///     auto r = simsr::check(exec::omp, mesh);  if (!r.ok()) std::cerr << r.summary();

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "detail/elements.hpp"
#include "tet_mesh.hpp"
#include "tri_mesh.hpp"

namespace simsr {

/// Options of check/validate.
struct ValidateOptions {
  /// A tet is degenerate when |volume| ≤ tol·ℓ³, a triangle when area ≤ tol·ℓ² (ℓ its longest
  /// edge): scale-invariant. For reference a regular tet has volume/ℓ³ ≈ 0.118. Negative: off.
  double degenerate_tolerance = 1e-10;
  /// Let validate accept tets of negative volume (check still counts them).
  bool allow_inverted = false;
};

/// How often one kind of problem occurs and its first (smallest) offending index, −1 if none.
struct ProblemCount {
  Index count = 0;
  Index first = -1;

  void add(Index i) {
    ++count;
    if (first < 0 || i < first) first = i;
  }
  void merge(const ProblemCount& o) {
    count += o.count;
    if (o.first >= 0 && (first < 0 || o.first < first)) first = o.first;
  }
};

/// What check found. Every element is classified by its first problem in the order
/// out-of-range index, repeated vertex, degenerate, inverted (so counts do not overlap);
/// vertex counts are separate.
struct MeshReport {
  ProblemCount non_finite_vertex;   ///< vertices with a NaN/inf coordinate
  ProblemCount unreferenced_vertex; ///< vertices in no element (informational, not an error)
  ProblemCount out_of_range;        ///< elements with a vertex index outside [0, #V)
  ProblemCount repeated_vertex;     ///< elements using one vertex twice
  ProblemCount degenerate;          ///< (near-)zero volume or area, see ValidateOptions
  ProblemCount inverted;            ///< tets of negative volume (always 0 for triangles)

  /// No problem except unreferenced vertices (and inverted tets when `allow_inverted`).
  bool ok(bool allow_inverted = false) const {
    return non_finite_vertex.count == 0 && out_of_range.count == 0 && repeated_vertex.count == 0 &&
           degenerate.count == 0 && (allow_inverted || inverted.count == 0);
  }
  /// One line per kind of problem found.
  std::string summary() const {
    std::ostringstream s;
    auto line = [&](const char* what, const ProblemCount& p) {
      if (p.count) s << what << ": " << p.count << " (first " << p.first << ")\n";
    };
    line("non-finite vertices", non_finite_vertex);
    line("unreferenced vertices", unreferenced_vertex);
    line("elements with an index out of range", out_of_range);
    line("elements with a repeated vertex", repeated_vertex);
    line("degenerate elements", degenerate);
    line("inverted elements", inverted);
    return s.str();
  }
};

namespace detail {

/// Element problem codes, in the order check classifies them.
enum class ElementProblem { none, out_of_range, repeated, degenerate, inverted };

/// Classifies element e (K corners) of E against vertices V; `measure` receives its signed volume (K=4) or area (K=3).
template <int K, class S, class DE>
ElementProblem classify(const Points<S>& V, const Eigen::MatrixBase<DE>& E, Index e, double tol, S& measure) {
  measure = S(0);
  for (int k = 0; k < K; ++k)
    if (E(e, k) < 0 || E(e, k) >= V.rows()) return ElementProblem::out_of_range;
  for (int k = 0; k < K; ++k)
    for (int l = k + 1; l < K; ++l)
      if (E(e, k) == E(e, l)) return ElementProblem::repeated;
  Vec3<S> x[K];
  for (int k = 0; k < K; ++k) x[k] = point(V, E(e, k));
  S l2 = S(0);
  for (int k = 0; k < K; ++k)
    for (int l = k + 1; l < K; ++l) l2 = std::max(l2, (x[k] - x[l]).squaredNorm());
  if constexpr (K == 4) {
    measure = tet_volume6(x[0], x[1], x[2], x[3]) / S(6);
    if (tol >= 0 && std::abs(measure) <= S(tol) * l2 * std::sqrt(l2)) return ElementProblem::degenerate;
    if (measure < S(0)) return ElementProblem::inverted;
  } else {
    measure = (x[1] - x[0]).cross(x[2] - x[0]).norm() / S(2);
    if (tol >= 0 && measure <= S(tol) * l2) return ElementProblem::degenerate;
  }
  return ElementProblem::none;
}

template <int K, exec::HostPolicy P, class S, class DE>
MeshReport check_elements(P policy, const Points<S>& V, const Eigen::MatrixBase<DE>& E, const ValidateOptions& opt) {
  MeshReport r = exec::parallel_reduce(
      policy, V.rows(), MeshReport{},
      [&](Index v) {
        MeshReport m;
        if (!V.row(v).allFinite()) m.non_finite_vertex.add(v);
        return m;
      },
      [](MeshReport a, const MeshReport& b) {
        a.non_finite_vertex.merge(b.non_finite_vertex);
        return a;
      });
  const MeshReport elements = exec::parallel_reduce(
      policy, E.rows(), MeshReport{},
      [&](Index e) {
        MeshReport m;
        S measure;
        switch (classify<K>(V, E, e, opt.degenerate_tolerance, measure)) {
          case ElementProblem::out_of_range: m.out_of_range.add(e); break;
          case ElementProblem::repeated: m.repeated_vertex.add(e); break;
          case ElementProblem::degenerate: m.degenerate.add(e); break;
          case ElementProblem::inverted: m.inverted.add(e); break;
          case ElementProblem::none: break;
        }
        return m;
      },
      [](MeshReport a, const MeshReport& b) {
        a.out_of_range.merge(b.out_of_range);
        a.repeated_vertex.merge(b.repeated_vertex);
        a.degenerate.merge(b.degenerate);
        a.inverted.merge(b.inverted);
        return a;
      });
  r.out_of_range = elements.out_of_range;
  r.repeated_vertex = elements.repeated_vertex;
  r.degenerate = elements.degenerate;
  r.inverted = elements.inverted;
  std::vector<char> used(static_cast<std::size_t>(V.rows()), 0);
  for (Index e = 0; e < E.rows(); ++e)
    for (int k = 0; k < K; ++k)
      if (E(e, k) >= 0 && E(e, k) < V.rows()) used[E(e, k)] = 1;
  for (Index v = 0; v < V.rows(); ++v)
    if (!used[v]) r.unreferenced_vertex.add(v);
  return r;
}

template <int K, class S, class DE>
void throw_first(const MeshReport& r, const Points<S>& V, const Eigen::MatrixBase<DE>& E, const ValidateOptions& opt) {
  const char* kind = element_kind(K);
  if (r.non_finite_vertex.count) {
    const Index v = r.non_finite_vertex.first;
    std::ostringstream s;
    s << "non-finite coordinate (" << V(v, 0) << ", " << V(v, 1) << ", " << V(v, 2) << ")";
    throw MeshError("vertex", v, s.str());
  }
  Index e = -1;
  for (const ProblemCount* p : {&r.out_of_range, &r.repeated_vertex, &r.degenerate, &r.inverted}) {
    if (p == &r.inverted && opt.allow_inverted) continue;
    if (p->first >= 0 && (e < 0 || p->first < e)) e = p->first;
  }
  if (e < 0) return;
  S measure;
  std::ostringstream s;
  s << "(";
  for (int k = 0; k < K; ++k) s << (k ? ", " : "") << E(e, k);
  s << ") ";
  switch (classify<K>(V, E, e, opt.degenerate_tolerance, measure)) {
    case ElementProblem::out_of_range: s << "has a vertex index outside [0, " << V.rows() << ")"; break;
    case ElementProblem::repeated: s << "uses a vertex twice"; break;
    case ElementProblem::degenerate:
      s << "is degenerate (" << (K == 4 ? "volume " : "area ") << measure << ", tolerance " << opt.degenerate_tolerance
        << " relative to the longest edge)";
      break;
    case ElementProblem::inverted: s << "is inverted (volume " << measure << ")"; break;
    case ElementProblem::none: s << "is valid"; break;
  }
  throw MeshError(kind, e, s.str());
}

}  // namespace detail

/// Counts the problems of a tet mesh (see MeshReport); never throws for bad data.
template <exec::HostPolicy P, class S>
MeshReport check(P policy, const TetMesh<S>& mesh, const ValidateOptions& options = {}) {
  return detail::check_elements<4>(policy, mesh.V, mesh.T, options);
}

/// Counts the problems of a triangle mesh (see MeshReport; `inverted` stays 0).
template <exec::HostPolicy P, class S>
MeshReport check(P policy, const TriMesh<S>& mesh, const ValidateOptions& options = {}) {
  return detail::check_elements<3>(policy, mesh.V, mesh.F, options);
}

/// Throws MeshError for the first problem of a tet mesh: a non-finite vertex coordinate (kind
/// "vertex", smallest such vertex) first, otherwise the smallest tet (kind "tet") with an index
/// outside [0, #V), a repeated vertex, |volume| ≤ tolerance·ℓ³, or a negative volume.
template <exec::HostPolicy P, class S>
void validate(P policy, const TetMesh<S>& mesh, const ValidateOptions& options = {}) {
  const MeshReport r = check(policy, mesh, options);
  if (!r.ok(options.allow_inverted)) detail::throw_first<4>(r, mesh.V, mesh.T, options);
}

/// As for tets: non-finite vertex, then the smallest triangle with an index out of range, a
/// repeated vertex, or area ≤ tolerance·ℓ² (kind "triangle").
template <exec::HostPolicy P, class S>
void validate(P policy, const TriMesh<S>& mesh, const ValidateOptions& options = {}) {
  const MeshReport r = check(policy, mesh, options);
  if (!r.ok()) detail::throw_first<3>(r, mesh.V, mesh.F, options);
}

}  // namespace simsr
