#pragma once
/// \file
/// SoftDECA's forward simulation on the layered template (softdeca supplement §1–2), one sample
/// of parameters at a time, with either solver over the same energy:
///
///   E = E_str(soft tissue; w_st, ε) + E_str(muscle; w_mu, ε) + E_vol(all tets; w_vol, v)
///     + E_curv(skin; w_curv) + E_tar(skin → the expression; w_tar) + E_dist2(skin; w_dist)
///     + gravity (1–2 g, any direction) + the implicit step's inertia (α, β, γ)
///
/// with the bones (cranium, jaw, the neck cut) as Dirichlet vertices at the sample's skull
/// scaling. E_dist2 keeps each skin vertex over bone at its template distance d_x from the bone
/// vertex beneath it (which moves with the skull), SoftDECA's "predicted distances" D(S) being
/// the template's tissue thickness here. E_tar's and E_dist2's weights are per unit skin area (each
/// vertex's Voronoi area times the stiffness), so they do not depend on the skin's resolution.
///
/// One sample runs in two parts:
///  1. the individual at rest: quasistatic, no expression (E_tar pulls to the neutral skin), the
///     skull scaled, gravity on, from the template carried along by its scaled bones;
///  2. the expression: `steps` implicit steps of length h from that state at rest, the target
///     blended from the neutral to the expression over the first half of the steps and held,
///     inertia α, damping β and momentum γ acting (with α = β = 0 every step is quasistatic).
/// The result is the skin at the last step (and at rest, for reference).
///
///     scenario::SoftDecaSimulator sim(tpl);
///     auto r = sim.simulate(exec::omp, params, expression_weights);          // local–global
///     auto n = sim.simulate(exec::omp, params, expression_weights, {.solver = SoftDecaSolver::newton});

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../../mesh/vertex_areas.hpp"
#include "../../physics/elastic_energy.hpp"
#include "../../physics/forces/gravity.hpp"
#include "../../physics/forces/implicit_inertia.hpp"
#include "../../physics/forces/surface_bending.hpp"
#include "../../physics/forces/vertex_targets.hpp"
#include "../../physics/local_global.hpp"
#include "../../physics/materials/strain_limit.hpp"
#include "../../physics/materials/volume_target.hpp"
#include "../../physics/quasistatic.hpp"
#include "template.hpp"
#include "parameters.hpp"

namespace simsr::scenario {

/// Which solver a SoftDECA simulation uses.
enum class SoftDecaSolver { local_global, newton };

/// The solver a name gives ("local_global" or "newton": `simsr datagen --solver`, Python's
/// `solver=`); ArgumentError naming the name otherwise.
inline SoftDecaSolver parse_softdeca_solver(const std::string& name) {
  if (name == "local_global") return SoftDecaSolver::local_global;
  if (name == "newton") return SoftDecaSolver::newton;
  throw ArgumentError("softdeca solver: local_global or newton (got '" + name + "')");
}

/// How one sample is simulated.
struct SoftDecaSimulationOptions {
  SoftDecaSolver solver = SoftDecaSolver::local_global;
  Index steps = 6;              ///< implicit steps from rest to the expression (≥ 1)
  double time_step = 1.0 / 30;  ///< h (s)
  double relative_tolerance = 1e-6;  ///< both solvers' gradient tolerance (NewtonOptions' meaning)
  Index max_iterations = 5000;  ///< local–global iterations per solve
  /// Newton iterations per solve: the Newton solver's own, and those finishing an unconverged
  /// local–global solve. A sample that Newton has not settled in a few dozen is one of the
  /// nonconvex ones (README, "SoftDECA": the exact Hessian indefinite at every iterate, linear
  /// convergence under either definiteness fix), so a smaller cap fails it sooner.
  Index newton_iterations = 100;
  Index history = 5;            ///< local–global L-BFGS memory
  /// Local–global only: a solve that stops without converging (max_iterations, or a line search
  /// that finds no decrease) is finished by Newton from where it stopped. Some sampled weight
  /// sets, 0.001 against 100, make the constant matrix a poor model and take thousands of
  /// iterations; off, such a sample is a ConvergenceError.
  bool newton_fallback = true;
};

/// What one sample gave.
struct SoftDecaResult {
  Points<> skin;          ///< #skin×3 at the last step (m)
  Points<> skin_at_rest;  ///< #skin×3 after part 1
  std::vector<Index> iterations;  ///< per solve (part 1, then each step): local–global's, plus Newton's where it finished
  Index newton_fallbacks = 0;     ///< solves that local–global left unconverged and Newton finished
  Index inverted_tets = 0;        ///< det F ≤ 0 at the last step
  double seconds = 0;
  Index total_iterations() const {
    Index s = 0;
    for (Index i : iterations) s += i;
    return s;
  }
};

/// The layered template's terms, built once and re-weighted per sample (see the file comment).
/// `Linear` factors both solvers' matrices: physics::SparseCholesky (Eigen's simplicial LDLᵀ, the
/// default) or, built with CHOLMOD, physics::CholmodCholesky (supernodal: what Newton needs at the
/// ICT template's size). SoftDecaSimulator is the default.
template <class Linear = physics::SparseCholesky<>>
class BasicSoftDecaSimulator {
 public:
  using StrainEnergy = physics::ElasticEnergy<physics::StrainLimit<>>;
  using VolumeEnergy = physics::ElasticEnergy<physics::VolumeTarget<>>;

  explicit BasicSoftDecaSimulator(const SoftDecaTemplate& tpl, SoftDecaStiffness k = {})
      : tpl_(tpl),
        k_(k),
        n_(tpl.head.mesh.num_vertices()),
        strain_soft_(layer(tpl, TissueLayer::soft_tissue), physics::StrainLimit<>(k.strain_soft_tissue)),
        strain_muscle_(layer(tpl, TissueLayer::muscle), physics::StrainLimit<>(k.strain_muscle)),
        volume_(tpl.head.mesh, physics::VolumeTarget<>(k.volume)),
        bending_(n_, tpl.head.mesh.V, tpl.skin_triangles, k.bending),
        targets_(physics::VertexTargets<>::attraction(n_, tpl.skin, skin_rest(tpl), VecX<>::Zero(tpl.skin.size()))),
        distances_(make_distances(tpl)),
        gravity_(tpl.head.mesh, k.density, Vec3<>(0, -k.gravity, 0)),
        inertia_(gravity_.masses(), tpl.head.mesh.V, {}),
        settle_(n_, tpl.head.mesh.T),
        step_(n_, tpl.head.mesh.T),
        newton_(n_, tpl.head.mesh.T) {
    // skin areas (per unit area weights): Voronoi areas of the skin triangles at rest
    const VecX<> all = voronoi_areas(tpl.head.mesh.V, tpl.skin_triangles);
    skin_area_.resize(tpl.skin.size());
    for (Index k2 = 0; k2 < tpl.skin.size(); ++k2) skin_area_[k2] = all[tpl.skin[k2]];
    distance_area_.resize(distances_.size());
    for (Index k2 = 0; k2 < distances_.size(); ++k2) distance_area_[k2] = all[distances_.vertices()[k2]];
    // outer vertices that pinched columns left without a tet (layered_head.hpp): a skin vertex is
    // held by E_tar; any other (a socket's) is held where its bones carry it, else it would be a
    // zero row of both solvers' matrices
    std::vector<char> in_tet(static_cast<std::size_t>(n_), 0), on_skin(static_cast<std::size_t>(n_), 0);
    for (Index t = 0; t < tpl.head.mesh.num_tets(); ++t)
      for (int c = 0; c < 4; ++c) in_tet[std::size_t(tpl.head.mesh.T(t, c))] = 1;
    for (Index k2 = 0; k2 < tpl.skin.size(); ++k2) on_skin[std::size_t(tpl.skin[k2])] = 1;
    for (Index v = 0; v < n_; ++v)
      if (!in_tet[std::size_t(v)] && !on_skin[std::size_t(v)] && tpl.head.bone[std::size_t(v)] == Bone::none) loose_.push_back(VIndex(v));
  }

  /// Vertices without a tet and off the skin, held at their place (see the constructor).
  const std::vector<VIndex>& loose_vertices() const { return loose_; }

  const SoftDecaTemplate& template_() const { return tpl_; }
  /// Skin vertices kept at a distance from the bone beneath them (E_dist2).
  Index distance_vertices() const { return distances_.size(); }

  /// One sample (see the file comment): prepare(), settle(), then `steps` calls of step() with
  /// the expression blended in over the first half. `expression` holds the E expression weights.
  /// Throws ConvergenceError from the solvers, ShapeError for a wrong number of weights,
  /// ArgumentError for parameters outside what the energies accept.
  template <exec::HostPolicy P>
  SoftDecaResult simulate(P policy, const SoftDecaParameters& p, const VecX<>& expression, const SoftDecaSimulationOptions& o = {}) {
    if (o.steps < 1) throw ArgumentError("SoftDecaSimulator: steps must be >= 1, got " + std::to_string(o.steps));
    check_expression(expression);
    const auto t0 = std::chrono::steady_clock::now();
    prepare(p);
    fallbacks_ = 0;
    SoftDecaResult r;
    Points<> x;
    r.iterations.push_back(settle(policy, x, o));
    r.skin_at_rest = skin_of(x);
    start_dynamics(x, o);
    const double ramp_steps = std::max(1.0, double(o.steps) / 2);
    for (Index s = 1; s <= o.steps; ++s) r.iterations.push_back(step(policy, x, std::min(1.0, double(s) / ramp_steps) * expression, o));
    r.skin = skin_of(x);
    r.inverted_tets = volume_.count_inverted(policy, x);
    r.newton_fallbacks = fallbacks_;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
  }

  /// The sample's weights, gravity and skull on every term (both solvers' matrices refactor).
  void prepare(const SoftDecaParameters& p) {
    p_ = p;
    strain_soft_.material() = physics::StrainLimit<>(k_.strain_soft_tissue * p.w_strain_soft_tissue, p.max_strain);
    strain_muscle_.material() = physics::StrainLimit<>(k_.strain_muscle * p.w_strain_muscle, p.max_strain);
    volume_.material() = physics::VolumeTarget<>(k_.volume * p.w_volume, p.volume_target);
    bending_.set_stiffness(k_.bending * p.w_bending);
    targets_.set_weights(k_.target * p.w_target * skin_area_);
    distances_.set_weights(k_.distance * p.w_distance * distance_area_);
    gravity_.set_acceleration(k_.gravity * p.gravity * p.gravity_direction.normalized());
    bones_ = tpl_.head.bone_targets(p.cranium_scale, p.jaw_scale);
    if (!loose_.empty()) {  // held with the cranium, merged into the sorted Dirichlet list
      const Points<> carried = tpl_.head.scaled_rest(p.cranium_scale, p.jaw_scale);
      std::vector<std::pair<VIndex, Vec3<>>> all;
      for (Index k2 = 0; k2 < bones_.size(); ++k2) all.emplace_back(bones_.vertices[k2], bones_.targets.row(k2).transpose());
      for (VIndex v : loose_) all.emplace_back(v, carried.row(v).transpose());
      std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      bones_.vertices.resize(Index(all.size()));
      bones_.targets.resize(Index(all.size()), 3);
      for (std::size_t k2 = 0; k2 < all.size(); ++k2) {
        bones_.vertices[Index(k2)] = all[k2].first;
        bones_.targets.row(Index(k2)) = all[k2].second.transpose();
      }
    }
    Points<> anchors(distances_.size(), 3);
    for (Index k2 = 0; k2 < distances_.size(); ++k2) anchors.row(k2) = bone_target(bones_, anchor_vertex_[std::size_t(k2)]);
    distances_.set_targets(anchors);
    settle_.invalidate();
    step_.invalidate();
  }

  /// Part 1: x = the individual at rest (quasistatic, no expression), from the template carried
  /// along by its bones. Returns the solver's iterations.
  template <exec::HostPolicy P>
  Index settle(P policy, Points<>& x, const SoftDecaSimulationOptions& o = {}) {
    x = tpl_.head.scaled_rest(p_.cranium_scale, p_.jaw_scale);
    targets_.set_targets(tpl_.expression(VecX<>::Zero(tpl_.expression_deltas.rows())));
    inertia_.set_parameters({.h = o.time_step, .alpha = 0, .beta = 0, .gamma = 0});
    return solve(policy, settle_, x, o);
  }

  /// Part 2 begins at rest at x: the dynamics' parameters set, the state's history reset.
  void start_dynamics(const Points<>& x, const SoftDecaSimulationOptions& o = {}) {
    inertia_.set_parameters({.h = o.time_step, .alpha = p_.alpha, .beta = p_.beta, .gamma = p_.gamma});
    inertia_.reset(x);
  }

  /// One implicit step toward the skin at expression weights `w` (x in/out; the state's history
  /// advances). Returns the solver's iterations.
  template <exec::HostPolicy P>
  Index step(P policy, Points<>& x, const VecX<>& w, const SoftDecaSimulationOptions& o = {}) {
    check_expression(w);
    targets_.set_targets(tpl_.expression(w));
    const Index its = solve(policy, step_, x, o);
    inertia_.advance(x);
    return its;
  }

  /// The step solver (local-global), for timing its parts: its factor() and apply_inverse().
  physics::LocalGlobalSolver<Linear>& step_solver() { return step_; }
  const physics::DirichletBoundary<>& boundary() const { return bones_; }
  /// Σ terms' gradients at x into g (#V×3): the local step of one local-global iteration.
  template <exec::HostPolicy P>
  void gradient(P policy, const Points<>& x, Points<>& g) const {
    g.setZero(x.rows(), 3);
    with_terms([&](const auto&... term) { (term.add_gradient(policy, x, g), ...); });
  }
  /// Σ terms' energies at x (J): what a line-search trial evaluates.
  template <exec::HostPolicy P>
  double energy(P policy, const Points<>& x) const {
    double magnitude = 0;
    return with_terms([&](const auto&... term) { return physics::detail::total_energy(policy, x, magnitude, term...); });
  }
  /// Σ terms' energies at x, and their gradients into g (#V×3), in one pass over each term that
  /// can (physics::detail::FusedEnergyGradient): what the local-global solver evaluates at a unit step.
  template <exec::HostPolicy P>
  double energy_and_gradient(P policy, const Points<>& x, Points<>& g) const {
    g.setZero(x.rows(), 3);
    double e = 0;  // a comma fold: the terms in order (a + fold leaves the order of their additions to g open)
    with_terms([&](const auto&... term) { ((e += physics::detail::add_energy_gradient(policy, term, x, g)), ...); });
    return e;
  }
  /// Factors the step solver's matrix for the current weights (what step() does once per sample).
  template <exec::HostPolicy P>
  void factor_step(P policy) {
    with_terms([&](const auto&... term) { step_.factor(policy, bones_, term...); });
  }

 private:
  /// f(every term of the energy), in one order: the one list the solvers, the gradient and the
  /// energy share (see the file comment).
  template <class F>
  decltype(auto) with_terms(F&& f) const {
    return f(strain_soft_, strain_muscle_, volume_, bending_, targets_, distances_, gravity_, inertia_);
  }

  static TetMesh<> layer(const SoftDecaTemplate& tpl, TissueLayer l) {
    std::vector<Index> rows;
    for (Index t = 0; t < tpl.head.mesh.num_tets(); ++t)
      if (tpl.head.tissue[std::size_t(t)] == l) rows.push_back(t);
    TetMesh<> m;
    m.V = tpl.head.mesh.V;
    m.T.resize(Index(rows.size()), 4);
    for (std::size_t r = 0; r < rows.size(); ++r) m.T.row(Index(r)) = tpl.head.mesh.T.row(rows[r]);
    return m;
  }
  static Points<> skin_rest(const SoftDecaTemplate& tpl) {
    Points<> s(tpl.skin.size(), 3);
    for (Index k = 0; k < tpl.skin.size(); ++k) s.row(k) = tpl.head.mesh.V.row(tpl.skin[k]);
    return s;
  }
  /// Skin vertices (outer wrap, index i) whose inner-wrap vertex vertex(2L, i) is cranium or jaw.
  physics::VertexTargets<> make_distances(const SoftDecaTemplate& tpl) {
    const LayeredHead& h = tpl.head;
    std::vector<VIndex> v;
    std::vector<double> d;
    for (Index k = 0; k < tpl.skin.size(); ++k) {
      const Index i = tpl.skin[k], b = h.vertex(2 * h.layers, i);
      if (b < 0) continue;
      const Bone bone = h.bone[std::size_t(b)];
      if (bone == Bone::cranium || bone == Bone::jaw) {
        v.push_back(VIndex(i));
        anchor_vertex_.push_back(VIndex(b));
        d.push_back((h.mesh.V.row(i) - h.mesh.V.row(b)).norm());
      }
    }
    const Index m = Index(v.size());
    Points<> s(m, 3);
    for (Index k = 0; k < m; ++k) s.row(k) = h.mesh.V.row(anchor_vertex_[std::size_t(k)]);
    return physics::VertexTargets<>(h.mesh.num_vertices(), Eigen::Map<const IndexVector>(v.data(), m), s,
                                    Eigen::Map<const VecX<>>(d.data(), m), VecX<>::Zero(m));
  }
  static Eigen::RowVector3d bone_target(const physics::DirichletBoundary<>& b, VIndex v) {
    const auto it = std::lower_bound(b.vertices.data(), b.vertices.data() + b.vertices.size(), v);
    return b.targets.row(Index(it - b.vertices.data()));
  }
  Points<> skin_of(const Points<>& x) const {
    Points<> s(tpl_.skin.size(), 3);
    for (Index k = 0; k < tpl_.skin.size(); ++k) s.row(k) = x.row(tpl_.skin[k]);
    return s;
  }
  void check_expression(const VecX<>& w) const {
    if (w.size() != tpl_.expression_deltas.rows()) throw ShapeError("SoftDecaSimulator: expression weights", {tpl_.expression_deltas.rows()}, {w.size()});
  }
  template <class P>
  Index solve(P policy, physics::LocalGlobalSolver<Linear>& pd, Points<>& x, const SoftDecaSimulationOptions& o) {
    const physics::DirichletBoundary<>& bones = bones_;
    // here, where every solve (simulate's, settle()'s and step()'s) takes its options
    if (o.max_iterations < 1 || o.newton_iterations < 1)
      throw ArgumentError("SoftDecaSimulator: max_iterations and newton_iterations must be >= 1, got " + std::to_string(o.max_iterations) + " and " +
                          std::to_string(o.newton_iterations));
    newton_.options().relative_tolerance = o.relative_tolerance;
    newton_.options().max_iterations = o.newton_iterations;
    if (o.solver == SoftDecaSolver::newton) {
      return with_terms([&](const auto&... term) { return newton_.solve(policy, x, bones, term...).iterations; });
    }
    pd.options().relative_tolerance = o.relative_tolerance;
    pd.options().max_iterations = o.max_iterations;
    pd.options().history = o.history;
    try {
      return with_terms([&](const auto&... term) { return pd.solve(policy, x, bones, term...).iterations; });
    } catch (const ConvergenceError& e) {
      if (!o.newton_fallback) throw;
      ++fallbacks_;  // x holds local–global's last iterate
      return Index(e.iterations()) + with_terms([&](const auto&... term) { return newton_.solve(policy, x, bones, term...).iterations; });
    }
  }

  const SoftDecaTemplate& tpl_;
  SoftDecaStiffness k_;
  Index n_;
  std::vector<VIndex> anchor_vertex_;  // before distances_ (filled by make_distances)
  StrainEnergy strain_soft_, strain_muscle_;
  VolumeEnergy volume_;
  physics::SurfaceBending<> bending_;
  physics::VertexTargets<> targets_;
  physics::VertexTargets<> distances_;
  physics::Gravity<> gravity_;
  physics::ImplicitInertia<> inertia_;
  physics::LocalGlobalSolver<Linear> settle_, step_;
  physics::QuasistaticSolver<Linear> newton_;
  VecX<> skin_area_, distance_area_;
  SoftDecaParameters p_;
  physics::DirichletBoundary<> bones_;
  std::vector<VIndex> loose_;
  Index fallbacks_ = 0;  // of the current simulate()
};

/// The simulator with Eigen's simplicial LDLᵀ (no optional dependency).
using SoftDecaSimulator = BasicSoftDecaSimulator<>;

}  // namespace simsr::scenario
