#pragma once
/// \file
/// A multigrid V-cycle as the preconditioner of ConjugateGradient, for the Newton systems of a
/// tet mesh. Geometric prolongations, algebraic coarse operators:
///
/// - The levels are BCC lattices of cell size 2h, 4h, … covering the mesh (discretize::bcc_lattice,
///   the same lattices the LR simulator uses), each coarsened further where it would keep more
///   than 1/8 of the vertices of the level before (LatticeHierarchyOptions::coarsening). Level
///   ℓ's vertices are embedded barycentrically in level ℓ+1's tets, so the prolongation P
///   interpolates linearly: it reproduces every affine displacement, rigid motions included — the
///   near-null space of elasticity that coarse levels must carry. (Vertices of a coarse level that
///   no finer vertex uses are dropped.)
/// - The coarse matrices are Galerkin products A_{ℓ+1} = Pᵀ A_ℓ P, recomputed at every compute(),
///   so whatever is in the Hessian (materials, springs, contact, bones) is in them too; in 3×3
///   blocks (BlockGalerkin) where P is vertex weights ⊗ I₃, as lattice_hierarchy's are. Rows of
///   Dirichlet DOFs (the identity rows BlockHessian::assemble writes) are left out of P: the
///   coarse levels never move a fixed DOF.
/// - Smoothing is damped block-Jacobi, x ← x + ω B⁻¹(b − A x) with B the 3×3 vertex blocks and
///   ω = 4 / (3 λ_max(B⁻¹A)) from a few power iterations per level (the usual safe choice: ω·λ_max
///   = 4/3 < 2 keeps every sweep a contraction in the A-norm). Pre- and post-smoothing use the same
///   sweep count, so the V-cycle is a symmetric positive definite operator, as PCG requires. Or
///   (MultigridOptions::Smoother::chebyshev) a Chebyshev polynomial in B⁻¹A on [λ_max/ratio, λ_max];
///   or (Smoother::gauss_seidel) multicolour block Gauss–Seidel, forward before and backward after.
/// - The coarsest level is solved exactly (Eigen's sparse LDLᵀ).
/// - The smoothing and residual products run on 3×3 block copies of the level matrices
///   (BlockCsr: a third fewer bytes per product than the scalar CSR, the same sums to rounding), or
///   with MultigridOptions::storage = block_single on copies whose values are stored in single
///   precision (half the bytes again; the sums stay in S, the V-cycle is then the one of the
///   rounded matrices, still symmetric: PCG's own products use A itself).
///
///     using Pcg = physics::ConjugateGradient<physics::Multigrid<>>;
///     physics::QuasistaticSolver<Pcg> newton(mesh.num_vertices(), mesh.T, {},
///         physics::make_linear_solver<Pcg>(exec::omp, mesh, {.tolerance = 1e-4}));   // levels: once per mesh
///     newton.solve(exec::omp, x, boundary, terms...);
///
/// Why: block-Jacobi PCG needs ~400 iterations per Newton system on the 73k-tet face lattice
/// (its error in smooth, long-wavelength modes decays slowly); the V-cycle removes those modes on
/// the coarse levels (benchmarks/bench_physics.cpp compares the two).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../../discretize/bcc_lattice.hpp"
#include "../../discretize/embedding.hpp"
#include "../../mesh/element_colouring.hpp"
#include "../../mesh/tet_mesh.hpp"
#include "../hessian.hpp"
#include "block_csr.hpp"
#include "block_galerkin.hpp"
#include "conjugate_gradient.hpp"
#include "sparse_cholesky.hpp"
#include "sparse_ops.hpp"

namespace simsr::physics {

/// Options of lattice_hierarchy.
struct LatticeHierarchyOptions {
  double h = 0;                    ///< cell size of the first coarse lattice (its first try, with `coarsening`); 0: 2 × the mesh's mean edge length
  Index max_coarse_vertices = 400;   ///< stop coarsening once a level has at most this many vertices
  int max_levels = 8;              ///< at most this many coarse levels
  /// Each coarse level aims at no more than 1/coarsening of the level before's vertices: where
  /// the lattice at the level's cell size (twice the last one's) keeps more, the cell size grows
  /// by 1.25× per try, at most `coarsening_tries` times. Why: a lattice that covers a level keeps
  /// every cell the level's boundary touches, so halving the resolution does not divide the
  /// vertex count by 8 as in a nested grid; on the 73k-tet bunny lattice the first coarse level
  /// kept 1/4.2 of the vertices, and its Galerkin matrix (153k blocks, 46 a row, against the fine
  /// level's 196k, 14 a row) cost almost as much per product as the finest's. 0: the cell size
  /// doubles per level, nothing more (the baseline).
  double coarsening = 8;
  int coarsening_tries = 6;
};

/// The levels of a multigrid hierarchy: `vertices[0]` is the mesh's, `vertices[ℓ]` (ℓ ≥ 1) those of
/// the ℓ-th coarse lattice; `prolongations[ℓ]` maps level ℓ+1's DOFs to level ℓ's (scalar,
/// DOF-level: P(3v+d, 3c+d) = w_vc, the barycentric weight of vertex v on coarse vertex c).
template <class S = Scalar>
struct LatticeHierarchy {
  std::vector<SparseMatrix<S>> prolongations;
  std::vector<Points<S>> vertices;
  Index num_levels() const { return Index(vertices.size()); }
};

/// BCC lattices of cell size h, 2h, 4h, … covering a tet mesh (each grown further where it keeps
/// too many vertices: LatticeHierarchyOptions::coarsening), and the prolongations between
/// them (see the file comment and LatticeHierarchy). Stops at `max_coarse_vertices`, at
/// `max_levels`, or when a level would not shrink below 60 % of the one before. Each level's
/// vertices are embedded in the next lattice under `policy` (same result under seq and omp).
/// Throws ArgumentError for an empty mesh or a bad h.
template <exec::HostPolicy Policy, class S>
LatticeHierarchy<S> lattice_hierarchy(Policy policy, const TetMesh<S>& mesh, const LatticeHierarchyOptions& options = {}) {
  if (mesh.num_vertices() == 0 || mesh.num_tets() == 0) throw ArgumentError("lattice_hierarchy: the mesh has no tets");
  double h = options.h;
  if (h == 0) {
    double sum = 0;
    Index count = 0;
    static constexpr int edges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    for (Index t = 0; t < mesh.num_tets(); ++t)
      for (const auto& e : edges) sum += double((mesh.V.row(mesh.T(t, e[0])) - mesh.V.row(mesh.T(t, e[1]))).norm()), ++count;
    h = 2 * sum / double(count);
  }
  if (!(h > 0) || !std::isfinite(h)) throw ArgumentError("lattice_hierarchy: cell size h = " + std::to_string(h) + " must be positive and finite");
  if (options.coarsening < 0 || !std::isfinite(options.coarsening) || (options.coarsening > 0 && options.coarsening <= 1))
    throw ArgumentError("lattice_hierarchy: coarsening = " + std::to_string(options.coarsening) + " must be 0 (off) or above 1");
  if (options.coarsening_tries < 0) throw ArgumentError("lattice_hierarchy: coarsening_tries must not be negative");

  LatticeHierarchy<S> out;
  out.vertices.push_back(mesh.V);
  TetMesh<S> current = mesh;
  for (int level = 0; level < options.max_levels && current.num_vertices() > options.max_coarse_vertices; ++level, h *= 2) {
    // the lattice at h, or (LatticeHierarchyOptions::coarsening) at the first of h·1.25^k that keeps
    // at most 1/coarsening of this level's vertices
    struct Candidate {
      TetMesh<S> lattice;
      Embedding<S> emb;
      std::vector<VIndex> renumber;  ///< lattice vertex → coarse vertex (−1: no finer vertex uses it)
      Index used = 0;
    };
    const auto candidate = [&](double cell) {
      Candidate c{discretize::bcc_lattice(current, cell).mesh, {}, {}, 0};
      c.emb = embed(policy, c.lattice, current.V);
      // keep only the lattice vertices some finer vertex uses (with a nonzero weight)
      c.renumber.assign(std::size_t(c.lattice.num_vertices()), VIndex(-1));
      for (Index q = 0; q < c.emb.size(); ++q)
        for (int k = 0; k < 4; ++k)
          if (c.emb.weights(q, k) != S(0) && c.renumber[std::size_t(c.lattice.T(c.emb.tet[q], k))] < 0)
            c.renumber[std::size_t(c.lattice.T(c.emb.tet[q], k))] = VIndex(c.used++);
      return c;
    };
    Candidate best = candidate(h);
    const auto enough = [&](const Candidate& c) { return options.coarsening == 0 || double(c.used) * options.coarsening <= double(current.num_vertices()); };
    for (int attempt = 0; attempt < options.coarsening_tries && !enough(best); ++attempt) {
      std::optional<Candidate> next;
      try {
        next = candidate(h * 1.25);
      } catch (const ArgumentError&) {  // a cell size past the level's extent keeps no cell: the last lattice stands
        break;
      }
      h *= 1.25;
      best = std::move(*next);
    }
    const TetMesh<S>& lattice = best.lattice;
    const Embedding<S>& emb = best.emb;
    const std::vector<VIndex>& renumber = best.renumber;
    const Index used = best.used;
    if (double(used) > 0.6 * double(current.num_vertices())) break;
    std::vector<Eigen::Triplet<S, int>> entries;
    entries.reserve(std::size_t(emb.size()) * 12);
    for (Index q = 0; q < emb.size(); ++q)
      for (int k = 0; k < 4; ++k) {
        const S w = emb.weights(q, k);
        if (w == S(0)) continue;
        const Index c = renumber[std::size_t(lattice.T(emb.tet[q], k))];
        for (int d = 0; d < 3; ++d) entries.emplace_back(int(3 * q + d), int(3 * c + d), w);
      }
    SparseMatrix<S> P(3 * current.num_vertices(), 3 * used);
    P.setFromTriplets(entries.begin(), entries.end());
    out.prolongations.push_back(std::move(P));
    // the next level coarsens the used part of this lattice: its used vertices, and the tets made of them only
    TetMesh<S> next;
    next.V.resize(used, 3);
    for (Index v = 0; v < lattice.num_vertices(); ++v)
      if (renumber[std::size_t(v)] >= 0) next.V.row(renumber[std::size_t(v)]) = lattice.V.row(v);
    std::vector<Index> keep;
    for (Index t = 0; t < lattice.num_tets(); ++t) {
      bool all = true;
      for (int k = 0; k < 4; ++k) all = all && renumber[std::size_t(lattice.T(t, k))] >= 0;
      if (all) keep.push_back(t);
    }
    next.T.resize(Index(keep.size()), 4);
    for (std::size_t i = 0; i < keep.size(); ++i)
      for (int k = 0; k < 4; ++k) next.T(Index(i), k) = renumber[std::size_t(lattice.T(keep[i], k))];
    out.vertices.push_back(next.V);
    if (next.num_tets() == 0) break;  // too coarse to go on: the last P stands, its level is the coarsest
    current = std::move(next);
  }
  return out;
}

/// Options of Multigrid.
struct MultigridOptions {
  int smoothing_sweeps = 1;    ///< damped block-Jacobi sweeps before and after each coarse correction
  double damping = 0;          ///< ω; 0: 4 / (3 λ_max(B⁻¹A)) estimated per level at compute()
  /// How λ_max(B⁻¹A) (ω's and the Chebyshev interval's) is estimated at each compute():
  /// - `power`: power iterations, `power_iterations` at the first compute() and
  ///   `warm_power_iterations` at later ones, started from the last estimate's vector.
  /// - `lanczos`: `lanczos_iterations` steps of block-Jacobi-preconditioned CG from a fixed vector,
  ///   λ the largest eigenvalue of their Lanczos tridiagonal (the estimate PETSc's and hypre's
  ///   Chebyshev smoothers make). A Krylov space finds an extreme eigenvalue in far fewer products
  ///   than the power method, whose few warm iterations lag when the matrix changes: on the coarse
  ///   face model's HR mesh, a frame whose lip contact switched on (one Newton iteration to the
  ///   next) had its finest level's λ under-estimated 2.0× and the coarse levels' 2.2–2.7× by the
  ///   power method (against 300 power iterations). The Chebyshev polynomial grows past 1 in
  ///   magnitude just 10% above its interval, so those modes were amplified, the V-cycle stopped
  ///   being positive definite, and PCG ran its full iteration count on the Newton system.
  ///   Starting cold at every compute() also makes a compute independent of the ones before it.
  /// - `automatic` (the default): `lanczos` for the Chebyshev smoother, `power` for Jacobi (whose
  ///   ω = 4 / (3λ) contracts up to 1.65× past the padded estimate).
  enum class Spectrum { automatic, power, lanczos };
  Spectrum spectrum = Spectrum::automatic;
  int power_iterations = 12;   ///< for the power estimate, at the first compute()
  int warm_power_iterations = 2;  ///< at later ones, started from the last estimate's vector
  int lanczos_iterations = 10;  ///< for the Lanczos estimate, at every compute()
  /// The coarse levels (Galerkin products, their smoothers, the coarsest factorization) are
  /// built by one compute() and kept for the next n − 1 (and rebuilt by the first after
  /// forget_estimates() or a change of the Dirichlet rows); between, a
  /// compute() refreshes only the finest level's smoother and ω, and the V-cycle corrects the
  /// new matrix's residual with the coarse levels of an earlier one. PCG only needs the
  /// preconditioner to be symmetric positive definite, not A's own: a lagged V-cycle costs some
  /// iterations and saves the setup (most of it the products PᵀAP) in Newton iterations and
  /// frames whose Hessians differ little. 1: rebuilt every time.
  int coarse_refresh_every = 1;
  /// How the levels' matrices are stored for the V-cycle's products (file comment): `csr` the
  /// scalar CSR itself (the baseline), `block` 3×3 blocks (the same V-cycle to rounding, fewer bytes),
  /// `block_single` 3×3 blocks of single-precision values (fewest bytes; the V-cycle of the
  /// rounded matrices).
  enum class Storage { csr, block, block_single };
  Storage storage = Storage::block;
  /// The smoother before and after each coarse correction: `jacobi`, `smoothing_sweeps` damped
  /// block-Jacobi sweeps (ω above); or `chebyshev`, the Chebyshev polynomial in B⁻¹A of degree
  /// `chebyshev_degree` that is smallest on [λ/chebyshev_ratio, λ], λ the padded estimate of
  /// λ_max(B⁻¹A) (Adams, Brezina, Hu & Tuminaro 2003, "Parallel multigrid smoothing: polynomial
  /// versus Gauss–Seidel", the recurrence of their §2). The same polynomial before and after keeps
  /// the V-cycle symmetric positive definite (its error factor lies in (−1, 1) on
  /// (0, λ (1 + 1/ratio))). Degree d costs d − 1 products of the level's matrix per smoothing
  /// beyond the residual's, where `smoothing_sweeps` Jacobi sweeps cost one each.
  ///
  /// Or `gauss_seidel`: `smoothing_sweeps` block Gauss–Seidel sweeps, x_v ← x_v + B_v⁻¹(b − A x)_v
  /// vertex by vertex with the newest x, the vertices in colours of the level's block pattern
  /// (greedy_graph_colouring: a colour's vertices couple to none of its others, so they update
  /// side by side, seq == omp bitwise). Colours in order before the coarse correction, in reverse
  /// after: the post-smoother is the pre-smoother's adjoint, so the V-cycle stays symmetric (and
  /// positive definite: block Gauss–Seidel contracts in the A-norm for any symmetric positive
  /// definite A, no damping or spectrum estimate needed). A sweep reads the level's matrix once,
  /// as a Jacobi sweep's residual does; the price is a parallel loop per colour instead of one.
  /// Needs the 3×3 blocks: Storage::block or block_single.
  enum class Smoother { jacobi, chebyshev, gauss_seidel };
  Smoother smoother = Smoother::jacobi;
  int chebyshev_degree = 2;
  double chebyshev_ratio = 10;
};

/// The V-cycle preconditioner (see the file comment). Movable; keeps its buffers between calls.
template <class S = Scalar>
class Multigrid {
 public:
  Multigrid() = default;
  /// `prolongations[ℓ]` maps level ℓ+1 to level ℓ (lattice_hierarchy). An empty list gives a
  /// one-level method: a direct solve of A (useful as a check, costly at scale).
  explicit Multigrid(std::vector<SparseMatrix<S>> prolongations, MultigridOptions options = {}) : options_(options) {
    if (options.smoothing_sweeps < 1) throw ArgumentError("Multigrid: smoothing_sweeps must be at least 1");
    if (options.power_iterations < 1 || options.warm_power_iterations < 1 || options.lanczos_iterations < 1)
      throw ArgumentError("Multigrid: power_iterations, warm_power_iterations and lanczos_iterations must be at least 1");
    if (options.damping < 0 || !(options.damping < 2)) throw ArgumentError("Multigrid: damping must be in [0, 2) (0: automatic)");
    if (options.coarse_refresh_every < 1) throw ArgumentError("Multigrid: coarse_refresh_every must be at least 1");
    if (options.chebyshev_degree < 1) throw ArgumentError("Multigrid: chebyshev_degree must be at least 1");
    if (!(options.chebyshev_ratio > 1) || !std::isfinite(options.chebyshev_ratio))
      throw ArgumentError("Multigrid: chebyshev_ratio must be a finite number above 1");
    if (options.smoother == MultigridOptions::Smoother::gauss_seidel && options.storage == MultigridOptions::Storage::csr)
      throw ArgumentError("Multigrid: the Gauss-Seidel smoother sweeps 3x3 vertex blocks: it needs storage block or block_single, not csr");
    for (std::size_t l = 0; l < prolongations.size(); ++l) {
      if (prolongations[l].rows() % 3 || prolongations[l].cols() % 3)
        throw ShapeError("Multigrid: prolongation " + std::to_string(l) + " (3 DOFs per vertex)", {-1, -1},
                         {prolongations[l].rows(), prolongations[l].cols()});
      if (l > 0 && prolongations[l].rows() != prolongations[l - 1].cols())
        throw ShapeError("Multigrid: prolongation " + std::to_string(l) + " rows (the columns of the one before)",
                         {prolongations[l - 1].cols(), -1}, {prolongations[l].rows(), prolongations[l].cols()});
    }
    levels_.resize(prolongations.size() + 1);
    for (std::size_t l = 0; l < prolongations.size(); ++l) {
      levels_[l].P_geometric = std::move(prolongations[l]);
      // the Galerkin product in blocks where P = W ⊗ I₃ (lattice_hierarchy's); any other P, scalar
      if (options_.storage != MultigridOptions::Storage::csr) levels_[l].W = vertex_weights(levels_[l].P_geometric);
    }
  }

  Index num_levels() const { return Index(levels_.size()); }
  /// DOFs of level ℓ (after compute()).
  Index level_size(Index l) const { return Index(levels_.at(std::size_t(l)).b.size()); }
  /// ω used on level ℓ by the last compute().
  double damping(Index l) const { return levels_.at(std::size_t(l)).omega; }
  /// The padded estimate of λ_max(B⁻¹A) on level ℓ by the last compute() (MultigridOptions::spectrum):
  /// the Chebyshev smoother's interval ends there.
  double spectrum_bound(Index l) const { return levels_.at(std::size_t(l)).lambda; }
  /// Forgets the power iterations' vectors: the next compute() starts cold, as the first did. A
  /// run that must not depend on its history (a resumed frame sequence, bitwise) calls it per frame.
  void forget_estimates() {
    for (Level& L : levels_) L.v.resize(0);
    computes_since_refresh_ = -1;
  }
  /// Whether the last compute() rebuilt the coarse levels (MultigridOptions::coarse_refresh_every).
  bool refreshed() const { return refreshed_; }

  /// Galerkin coarse operators, smoothers and the coarsest factorization for A. The structures
  /// of the products and the coarsest symbolic factorization are kept while A's pattern stays.
  /// A coarse operator that is not positive definite (A is not) is a ConvergenceError, the
  /// signal QuasistaticSolver takes to fall back from the exact to the projected Hessian.
  template <exec::HostPolicy P>
  void compute(P policy, const SparseMatrix<S>& A) {
    compute_levels(policy, A, nullptr);
  }
  /// The same, with A's 3×3 block copy already made (ConjugateGradient's, for its own products):
  /// the finest level reads it instead of copying A again. It must outlive the apply() calls.
  template <exec::HostPolicy P>
  void compute(P policy, const SparseMatrix<S>& A, const BlockCsr<S, S>& blocks) {
    if (blocks.rows() != A.rows() || blocks.cols() != A.cols())
      throw ShapeError("Multigrid: the block copy of the matrix", {A.rows(), A.cols()}, {blocks.rows(), blocks.cols()});
    compute_levels(policy, A, &blocks);
  }

 private:
  template <exec::HostPolicy P>
  void compute_levels(P policy, const SparseMatrix<S>& A, const BlockCsr<S, S>* given_blocks) {
    if (levels_.empty()) levels_.resize(1);
    levels_[0].given_blocks = given_blocks;
    if (A.rows() != A.cols()) throw ShapeError("Multigrid: matrix", {A.rows(), A.rows()}, {A.rows(), A.cols()});
    if (levels_.size() > 1 && levels_[0].P_geometric.rows() != A.rows())
      throw ShapeError("Multigrid: matrix (rows of the first prolongation)", {levels_[0].P_geometric.rows(), levels_[0].P_geometric.rows()},
                       {A.rows(), A.cols()});
    levels_[0].A_ref = &A;
    // lagged coarse levels: only level 0's smoother and ω (its residuals use A itself)
    bool stale = computes_since_refresh_ < 0 || levels_.size() == 1 || levels_[0].b.size() != A.rows() ||
                 levels_[0].P.rows() != A.rows() || computes_since_refresh_ + 1 >= options_.coarse_refresh_every;
    if (!stale) {  // the coarse levels must not move a DOF that is fixed now: the same Dirichlet rows, or a rebuild
      decoupled_rows(policy, A, decoupled_now_);
      stale = decoupled_now_ != levels_[0].decoupled;
    }
    refreshed_ = stale;
    if (!stale) {
      ++computes_since_refresh_;
      Level& L = levels_[0];
      store_blocks(policy, L, false);
      L.smoother.compute(policy, A);
      set_spectrum(policy, L);
      return;
    }
    computes_since_refresh_ = 0;
    for (std::size_t l = 0; l < levels_.size(); ++l) {
      Level& L = levels_[l];
      const SparseMatrix<S>& Al = L.matrix();
      const Index n = Al.rows();
      if (L.b.size() != n) {
        L.b.setZero(n);
        L.x.setZero(n);
        L.r.setZero(n);
        L.t.setZero(n);
        if (options_.smoother == MultigridOptions::Smoother::chebyshev) L.d.setZero(n);
        L.v.resize(0);
      }
      if (l + 1 == levels_.size()) {
        factorize_coarsest(policy, Al, l > 0 ? coarse_structure_version(levels_[l - 1]) : ++direct_version_);
        break;
      }
      store_blocks(policy, L, true);
      L.smoother.compute(policy, Al);
      set_spectrum(policy, L);
      galerkin(policy, l);
    }
  }


 public:
  /// z = one V-cycle applied to r (z ≈ A⁻¹ r).
  template <exec::HostPolicy P>
  void apply(P policy, const VecX<S>& r, VecX<S>& z) {
    if (levels_.empty() || levels_[0].b.size() != r.size())
      throw Error("Multigrid::apply before compute, or with a vector of another size");
    levels_[0].b = r;
    cycle(policy, 0);
    z = levels_[0].x;
  }

 private:
  struct Level {
    SparseMatrix<S> P_geometric;  ///< to this level from the next coarser one (empty on the coarsest)
    SparseMatrix<S> P, Pt;        ///< P_geometric with Dirichlet rows zeroed, and its transpose
    std::vector<Index> pt_source;  ///< Pt's entry k is P's entry pt_source[k]
    SparseProduct<S> ap, galerkin;  ///< A·P, then Pᵀ·(A·P) = the next level's matrix (Storage::csr)
    std::optional<SparseMatrix<S>> W;  ///< P_geometric's vertex weights, where it is W ⊗ I₃ (block storages)
    BlockGalerkin<S> block_galerkin;  ///< Pᵀ A P in 3×3 blocks (where W is)
    std::vector<char> decoupled;
    const SparseMatrix<S>* A_ref = nullptr;  ///< the caller's matrix (level 0)
    const SparseMatrix<S>* A_coarse = nullptr;  ///< the previous level's Galerkin product (levels ≥ 1)
    BlockJacobi<S> smoother;
    BlockCsr<S, S> block;             ///< the matrix as 3×3 blocks (Storage::block; BlockGalerkin's input)
    BlockCsr<S, float> block_single;  ///< … of single-precision values (Storage::block_single)
    const BlockCsr<S, S>* given_blocks = nullptr;  ///< level 0: the caller's block copy of A, if it gave one
    const BlockCsr<S, S>& blocks() const { return given_blocks ? *given_blocks : block; }
    double omega = 1;
    double lambda = 1;  ///< the padded estimate of λ_max(B⁻¹A) (the Chebyshev smoother's interval)
    /// v: the power iteration's vector, kept as the next compute's start (Spectrum::lanczos: the
    /// CG direction, with x its product; both scratch, as b, r and t are outside the V-cycle)
    VecX<S> b, x, r, t, v;
    VecX<S> d;              ///< the Chebyshev smoother's direction
    ElementColouring colours;  ///< the Gauss–Seidel smoother's vertex colours (greedy_graph_colouring of the blocks)
    std::uint64_t coloured_version = 0;  ///< … of the blocks of this BlockCsr::pattern_version (0: none yet)
    const SparseMatrix<S>& matrix() const { return A_ref ? *A_ref : *A_coarse; }
  };

  /// A_{l+1} = Pᵀ A_l P with the rows of decoupled (Dirichlet) DOFs of P zeroed.
  template <exec::HostPolicy P>
  void galerkin(P policy, std::size_t l) {
    Level& L = levels_[l];
    const SparseMatrix<S>& A = L.matrix();
    if (L.P.nonZeros() != L.P_geometric.nonZeros()) {  // first call: P's structure, Pt and its source map
      L.P = L.P_geometric;
      L.Pt = L.P_geometric.transpose();
      // entry numbers carried through the same transpose (in double: exact for any S)
      Eigen::SparseMatrix<double, Eigen::RowMajor, int> ids = L.P_geometric.template cast<double>();
      for (Index k = 0; k < ids.nonZeros(); ++k) ids.valuePtr()[k] = double(k);
      const Eigen::SparseMatrix<double, Eigen::RowMajor, int> ids_t = ids.transpose();
      L.pt_source.resize(std::size_t(ids_t.nonZeros()));
      for (Index k = 0; k < ids_t.nonZeros(); ++k) L.pt_source[std::size_t(k)] = Index(ids_t.valuePtr()[k]);
    }
    decoupled_rows(policy, A, L.decoupled);
    const S* geo = L.P_geometric.valuePtr();
    S* pv = L.P.valuePtr();
    const auto* po = L.P.outerIndexPtr();
    exec::parallel_for(policy, L.P.rows(), [&](Index r) {
      for (auto k = po[r]; k < po[r + 1]; ++k) pv[k] = L.decoupled[std::size_t(r)] ? S(0) : geo[k];
    });
    S* ptv = L.Pt.valuePtr();
    exec::parallel_for(policy, L.Pt.nonZeros(), [&](Index k) { ptv[k] = pv[L.pt_source[std::size_t(k)]]; });
    if (L.W) {
      L.block_galerkin.compute(policy, L.blocks(), *L.W, L.decoupled);
    } else {
      const SparseMatrix<S>& AP = L.ap.compute(policy, A, L.P);
      L.galerkin.compute(policy, L.Pt, AP);
    }
    SparseMatrix<S>& Ac = L.W ? L.block_galerkin.result() : L.galerkin.result();
    // a coarse DOF all of whose fine DOFs are fixed has a zero row: make it an identity row
    for (Index r = 0; r < Ac.rows(); ++r) {
      S* diag = nullptr;
      bool zero_row = true;
      for (typename SparseMatrix<S>::InnerIterator it(Ac, r); it; ++it) {
        if (it.col() == r) diag = &it.valueRef();
        zero_row = zero_row && it.value() == S(0);
      }
      if (!diag) throw Error("Multigrid: coarse level " + std::to_string(l + 1) + " has no diagonal entry at DOF " + std::to_string(r) +
                             " (does A store its diagonal?)");
      if (zero_row) *diag = S(1);
      else if (!(*diag > S(0)))
        throw ConvergenceError("Multigrid: coarse level " + std::to_string(l + 1) + " has a non-positive diagonal at DOF " +
                                   std::to_string(r) + ": A is not positive definite",
                               0, std::numeric_limits<double>::quiet_NaN());
    }
    levels_[l + 1].A_coarse = &Ac;
  }

  static std::uint64_t coarse_structure_version(const Level& L) {
    return L.W ? L.block_galerkin.structure_version() : L.galerkin.structure_version();
  }

  /// Sparse LDLᵀ of the coarsest matrix (SparseCholesky: the symbolic analysis only when its
  /// structure changed). Near the mesh's boundary a coarse vertex can be used by a single fine
  /// vertex, so P's columns can be linearly dependent and PᵀAP only semidefinite: Galerkin levels
  /// are factorized with a diagonal shift of 1e-10 × the largest diagonal entry. Directions in P's
  /// null space never reach the fine level (P maps them to 0), so the shift changes nothing else;
  /// an indefinite A still shows up as a negative pivot.
  template <exec::HostPolicy P>
  void factorize_coarsest(P policy, const SparseMatrix<S>& A, std::uint64_t structure) {
    if (!coarse_solver_) coarse_solver_.emplace(levels_.size() > 1 ? 1e-10 : 0.0);
    coarse_solver_->compute(policy, A, structure);
    if (!coarse_solver_->positive_definite())
      throw ConvergenceError("Multigrid: the coarsest level (" + std::to_string(A.rows()) + " DOFs) is not positive definite, so neither is A",
                             0, std::numeric_limits<double>::quiet_NaN());
  }

  /// Rows whose off-diagonal entries are all zero (the identity rows of Dirichlet DOFs).
  template <exec::HostPolicy P>
  static void decoupled_rows(P policy, const SparseMatrix<S>& A, std::vector<char>& out) {
    out.resize(std::size_t(A.rows()));
    exec::parallel_for(policy, A.rows(), [&](Index r) {
      char decoupled = 1;
      for (typename SparseMatrix<S>::InnerIterator it(A, r); it && decoupled; ++it) decoupled = !(it.col() != r && it.value() != S(0));
      out[std::size_t(r)] = decoupled;
    });
  }

  /// The estimates' fixed start vector (the same for every run: a compute depends on its matrix).
  static void fixed_start(VecX<S>& u, Index n) {
    u.resize(n);
    for (Index i = 0; i < n; ++i) u[i] = S(1) + S(0.5) * S(std::sin(double(i) * 0.7));
  }

  /// λ_max(B⁻¹A) by power iteration on AB⁻¹ (same eigenvalues): u ← A B⁻¹ u / ‖·‖, with the
  /// B-Rayleigh quotient of v = B⁻¹u, vᵀAv / vᵀBv = vᵀ(Av) / vᵀu, which needs B⁻¹ only. The first
  /// compute starts from a fixed vector and runs `power_iterations`; later ones start from the
  /// last vector (the Hessian changes little between Newton iterations) and run
  /// `warm_power_iterations`.
  template <exec::HostPolicy P>
  double lambda_max(P policy, Level& L) {
    const SparseMatrix<S>& A = L.matrix();
    VecX<S>& u = L.v;
    int iterations = options_.warm_power_iterations;
    if (u.size() != A.rows()) {
      fixed_start(u, A.rows());
      iterations = options_.power_iterations;
    }
    double lambda = 1;
    for (int k = 0; k < iterations; ++k) {
      L.smoother.apply(policy, u, L.r);   // v = B⁻¹ u
      multiply(policy, L, L.r, L.t);      // A v
      const double vBv = double(dot(policy, L.r, u));
      if (vBv > 0) lambda = std::max(lambda, double(dot(policy, L.r, L.t)) / vBv);
      const S norm = std::sqrt(dot(policy, L.t, L.t));
      if (!(norm > S(0))) break;
      u = L.t / norm;
    }
    // a Rayleigh quotient is a lower bound of λ_max: pad it so ω·λ_max stays well below 2
    return std::max(1.0, 1.1 * lambda);
  }

  /// λ_max(B⁻¹A) by Lanczos (MultigridOptions::Spectrum::lanczos): CG on A y = A u preconditioned
  /// by B⁻¹, u a fixed vector, whose coefficients α_j, β_j give the Lanczos tridiagonal of B⁻¹A in
  /// the B-inner product (Saad, "Iterative methods for sparse linear systems", §6.7.3):
  /// T_jj = 1/α_j + β_{j−1}/α_{j−1}, T_{j,j+1} = √β_j / α_j. Its largest eigenvalue (a Ritz
  /// value, a lower bound of λ_max) is padded by 1.1 as the power estimate is. A step that meets
  /// non-positive curvature (A or B not positive definite) ends the estimate with the steps before it.
  template <exec::HostPolicy P>
  double lanczos_lambda_max(P policy, Level& L) {
    const Index n = L.matrix().rows();
    const int m_max = options_.lanczos_iterations;
    VecX<S>&r = L.r, &z = L.t, &p = L.v, &q = L.x;
    r.resize(n);
    z.resize(n);
    p.resize(n);
    q.resize(n);
    // the start A u, u fixed: a Galerkin level can hold a DOF that almost no fine DOF reaches, whose
    // row of A and diagonal block are many orders of magnitude below the others'; there B⁻¹ of a
    // unit vector is as many above, and swamps the recurrence (measured: a 1,539-DOF level's first
    // r·z 1e178, one step, λ 0.9 against 7.3), while B⁻¹(A u) is of the order of u everywhere
    fixed_start(p, n);
    multiply(policy, L, p, r);
    L.smoother.apply(policy, r, z);
    p = z;
    double rz = double(dot(policy, r, z));
    std::vector<double>&alpha = lanczos_alpha_, &beta = lanczos_beta_;  // kept: no allocation once warm
    alpha.clear();
    beta.clear();
    if (rz > 0)
      for (int j = 0; j < m_max; ++j) {
        multiply(policy, L, p, q);
        const double pq = double(dot(policy, p, q));
        if (!(pq > 0)) break;
        alpha.push_back(rz / pq);
        const S a = S(alpha.back());
        exec::parallel_for(policy, n, [&](Index i) { r[i] -= a * q[i]; });
        L.smoother.apply(policy, r, z);
        const double rz_next = double(dot(policy, r, z));
        if (!(rz_next > 1e-30 * rz) || j + 1 == m_max) break;  // converged (or B indefinite), or the last step
        beta.push_back(rz_next / rz);
        rz = rz_next;
        const S b = S(beta.back());
        exec::parallel_for(policy, n, [&](Index i) { p[i] = z[i] + b * p[i]; });
      }
    const Index m = Index(alpha.size());
    if (m == 0) return 1.0;
    Eigen::VectorXd &diagonal = lanczos_diagonal_, &off = lanczos_off_;
    diagonal.resize(m);
    off.resize(m - 1);
    for (Index j = 0; j < m; ++j) {
      diagonal[j] = 1 / alpha[std::size_t(j)] + (j > 0 ? beta[std::size_t(j - 1)] / alpha[std::size_t(j - 1)] : 0.0);
      if (j + 1 < m) off[j] = std::sqrt(beta[std::size_t(j)]) / alpha[std::size_t(j)];
    }
    lanczos_eigen_.computeFromTridiagonal(diagonal, off, Eigen::EigenvaluesOnly);
    return std::max(1.0, 1.1 * lanczos_eigen_.eigenvalues().maxCoeff());
  }

  /// ω (Jacobi) and λ (Chebyshev) of a level whose smoother was just computed. A given damping
  /// skips the power iteration only where Jacobi alone uses it.
  template <exec::HostPolicy P>
  void set_spectrum(P policy, Level& L) {
    const bool chebyshev = options_.smoother == MultigridOptions::Smoother::chebyshev;
    if (options_.smoother == MultigridOptions::Smoother::gauss_seidel) return;  // needs neither
    if (options_.damping > 0 && !chebyshev) {
      L.omega = options_.damping;
      return;
    }
    const bool lanczos = options_.spectrum == MultigridOptions::Spectrum::lanczos || (options_.spectrum == MultigridOptions::Spectrum::automatic && chebyshev);
    L.lambda = lanczos ? lanczos_lambda_max(policy, L) : lambda_max(policy, L);
    L.omega = options_.damping > 0 ? options_.damping : 4.0 / (3.0 * L.lambda);
  }

  /// x ← x + p(B⁻¹A) B⁻¹ (b − A x): the Chebyshev smoother (MultigridOptions::Smoother), from
  /// x = 0 (`from_zero`: the residual is b, no product) or from the current x.
  template <exec::HostPolicy P>
  void chebyshev_smooth(P policy, Level& L, bool from_zero) {
    const S hi = S(L.lambda), lo = S(L.lambda / options_.chebyshev_ratio);
    const S theta = S(0.5) * (hi + lo), delta = S(0.5) * (hi - lo), sigma = theta / delta;
    if (from_zero)
      L.r = L.b;
    else
      residual(policy, L);
    L.smoother.apply(policy, L.r, L.t);
    const S inv_theta = S(1) / theta;
    exec::parallel_for(policy, L.x.size(), [&](Index i) { L.d[i] = inv_theta * L.t[i]; });
    S rho = S(1) / sigma;
    for (int k = 1;; ++k) {
      exec::parallel_for(policy, L.x.size(), [&](Index i) { L.x[i] += L.d[i]; });
      if (k == options_.chebyshev_degree) break;
      multiply(policy, L, L.d, L.t);
      exec::parallel_for(policy, L.x.size(), [&](Index i) { L.r[i] -= L.t[i]; });
      L.smoother.apply(policy, L.r, L.t);
      const S rho_next = S(1) / (S(2) * sigma - rho);
      const S keep = rho_next * rho, step = S(2) * rho_next / delta;
      exec::parallel_for(policy, L.x.size(), [&](Index i) { L.d[i] = keep * L.d[i] + step * L.t[i]; });
      rho = rho_next;
    }
  }

  /// One V-cycle from level l: x_l ≈ A_l⁻¹ b_l, starting from x_l = 0.
  template <exec::HostPolicy P>
  void cycle(P policy, std::size_t l) {
    Level& L = levels_[l];
    if (l + 1 == levels_.size()) {
      coarse_solver_->solve(policy, L.b, L.x);
      return;
    }
    L.x.setZero();
    // `pre`: the smoothing before the coarse correction (from x = 0), else after it
    auto smooth = [&](bool pre) {
      switch (options_.smoother) {
        case MultigridOptions::Smoother::gauss_seidel:
          if (options_.storage == MultigridOptions::Storage::block_single)
            return gauss_seidel(policy, L, L.block_single, pre, options_.smoothing_sweeps);
          return gauss_seidel(policy, L, L.blocks(), pre, options_.smoothing_sweeps);
        case MultigridOptions::Smoother::chebyshev: return chebyshev_smooth(policy, L, pre);
        case MultigridOptions::Smoother::jacobi:
          for (int s = 0; s < options_.smoothing_sweeps; ++s) {
            if (pre && s == 0)
              L.r = L.b;
            else
              residual(policy, L);
            L.smoother.apply(policy, L.r, L.t);
            const S w = S(L.omega);
            exec::parallel_for(policy, L.x.size(), [&](Index i) { L.x[i] += w * L.t[i]; });
          }
          return;
      }
    };
    smooth(true);
    residual(policy, L);
    Level& C = levels_[l + 1];
    sparse_multiply(policy, L.Pt, L.r, C.b);
    cycle(policy, l + 1);
    sparse_multiply(policy, L.P, C.x, L.t);
    exec::parallel_for(policy, L.x.size(), [&](Index i) { L.x[i] += L.t[i]; });
    smooth(false);
  }

  /// L.r = L.b − A L.x
  template <exec::HostPolicy P>
  void residual(P policy, Level& L) const {
    multiply(policy, L, L.x, L.r);
    exec::parallel_for(policy, L.r.size(), [&](Index i) { L.r[i] = L.b[i] - L.r[i]; });
  }

  /// The level's copy for the V-cycle's products (MultigridOptions::storage), from its matrix.
  /// The double blocks where the products or (`galerkin`: a rebuild) BlockGalerkin read them and
  /// the caller gave none; the single-precision ones for Storage::block_single.
  template <exec::HostPolicy P>
  void store_blocks(P policy, Level& L, bool galerkin) const {
    using enum MultigridOptions::Storage;
    if (!L.given_blocks && (options_.storage == block || (galerkin && L.W))) L.block.assign(policy, L.matrix());
    if (options_.storage == block_single) L.block_single.assign(policy, L.matrix());
    if (options_.smoother == MultigridOptions::Smoother::gauss_seidel) {
      // the colours of the blocks the sweeps read, made again only when their pattern changed
      // (pattern versions are unique over all BlockCsr objects: the version alone names the pattern)
      const auto colour = [&](const auto& blocks) {
        if (L.coloured_version == blocks.pattern_version()) return;
        L.colours = greedy_graph_colouring(blocks.block_outer(), blocks.block_inner(), blocks.rows() / 3);
        L.coloured_version = blocks.pattern_version();
      };
      if (options_.storage == block_single)
        colour(L.block_single);
      else
        colour(L.blocks());
    }
  }

  /// `sweeps` block Gauss–Seidel sweeps on level L (Smoother::gauss_seidel): the colours in order
  /// (`forward`) or in reverse. Each vertex v of a colour: x_v += B_v⁻¹ (b − A x)_v, its row read
  /// from the level's blocks; no two vertices of a colour couple, so the order within one is free.
  template <exec::HostPolicy P, class Value>
  void gauss_seidel(P policy, Level& L, const BlockCsr<S, Value>& A, bool forward, int sweeps) const {
    const int* outer = A.block_outer();
    const int* inner = A.block_inner();
    const Value* values = A.block_values();
    const S* b = L.b.data();
    S* x = L.x.data();
    const ElementColouring& c = L.colours;
    const Index colours = c.num_colours();
    for (int s = 0; s < sweeps; ++s)
      for (Index q = 0; q < colours; ++q) {
        const Index k = forward ? q : colours - 1 - q;
        const Index* rows = c.elements.data() + c.offsets[std::size_t(k)];
        exec::parallel_for(policy, c.size(k), [&, rows](Index i) {
          const Index v = rows[i];
          const detail::BlockRowSum<S> ax = detail::block_row_sum(outer, inner, values, x, v);
          const S r0 = b[3 * v] - ax.s0, r1 = b[3 * v + 1] - ax.s1, r2 = b[3 * v + 2] - ax.s2;
          const Mat3<S>& D = L.smoother.inverse_block(v);
          x[3 * v] += D(0, 0) * r0 + D(0, 1) * r1 + D(0, 2) * r2;
          x[3 * v + 1] += D(1, 0) * r0 + D(1, 1) * r1 + D(1, 2) * r2;
          x[3 * v + 2] += D(2, 0) * r0 + D(2, 1) * r1 + D(2, 2) * r2;
        });
      }
  }

  /// y = A_l x on the storage of MultigridOptions::storage.
  template <exec::HostPolicy P>
  void multiply(P policy, const Level& L, const VecX<S>& x, VecX<S>& y) const {
    switch (options_.storage) {
      case MultigridOptions::Storage::block: L.blocks().multiply(policy, x, y); break;
      case MultigridOptions::Storage::block_single: L.block_single.multiply(policy, x, y); break;
      case MultigridOptions::Storage::csr: sparse_multiply(policy, L.matrix(), x, y); break;
    }
  }

  MultigridOptions options_;
  std::vector<Level> levels_;
  std::uint64_t direct_version_ = 0;  ///< without coarse levels A's pattern is unknown here: analyze every time
  int computes_since_refresh_ = -1;   ///< computes since the coarse levels were built (-1: never, or forgotten)
  bool refreshed_ = false;
  // the Lanczos estimate's coefficients and tridiagonal (lanczos_lambda_max), kept between computes
  std::vector<double> lanczos_alpha_, lanczos_beta_;
  Eigen::VectorXd lanczos_diagonal_, lanczos_off_;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> lanczos_eigen_;
  std::vector<char> decoupled_now_;  ///< a lagged compute()'s Dirichlet rows, checked against level 0's
  std::optional<SparseCholesky<S>> coarse_solver_;
};

/// Whether a linear solver is PCG preconditioned by Multigrid (it needs the mesh to be built:
/// see make_linear_solver).
template <class L>
inline constexpr bool is_multigrid_pcg = false;
template <class S>
inline constexpr bool is_multigrid_pcg<ConjugateGradient<Multigrid<S>, S>> = true;

/// A linear solver for Newton on `mesh`: Linear{} (with `options` where Linear is a
/// ConjugateGradient), or, for PCG with Multigrid, one with the mesh's lattice hierarchy (built
/// under `policy`: lattice_hierarchy) and the `multigrid` options.
template <class Linear, exec::HostPolicy P, class S>
Linear make_linear_solver(P policy, const TetMesh<S>& mesh, const ConjugateGradientOptions& options = {},
                          const LatticeHierarchyOptions& levels = {}, const MultigridOptions& multigrid = {}) {
  static_assert(assert_linear_solver<Linear>());
  if constexpr (is_multigrid_pcg<Linear>)
    return Linear(options, Multigrid<typename Linear::scalar_type>(lattice_hierarchy(policy, mesh, levels).prolongations, multigrid));
  else if constexpr (requires { Linear(options); })
    return Linear(options);
  else
    return Linear{};
}

}  // namespace simsr::physics
