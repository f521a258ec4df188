#pragma once
/// \file
/// One face simulator, two resolutions (core paper §4): the same anatomy, controls and parameters
/// on the HR conforming mesh or the LR split lattice. A frame is a quasistatic solve, warm-started
/// from the previous frame, of
///
///     E(x) = Σ_t V_t ψ(F_t)                                 Mooney–Rivlin flesh (+ muscle fibres)
///          + Σ_i κ A_i / 2 ‖x(p_i) − b_i(w)‖²                track springs to the blendshapes
///          + lip contact (HR only)
///
/// with the bones as Dirichlet conditions: cranium fixed, jaw rotated about the hinge (two rigid
/// bones, face_model.hpp step 5). b_i(w) = neutral_i + Σ_e w_e δ_ei is the kit's
/// blendshape combination at surface vertex i (the paper's "blendshape muscle rig"), x(p_i) the
/// simulated position of that material point (an HR vertex, or its embedding in an LR tet), A_i
/// its rest Voronoi area: stiffness per unit area, so both meshes feel the same pull. Parameters
/// are per unit volume and area throughout (SPEC §3), so bulk behaviour agrees across resolutions
/// and what differs is the discretization, as in the paper's Fig. 4.
///
///     scenario::FaceSimulator<> hr(exec::omp, face, scenario::FaceResolution::high);
///     hr.set_controls(controls_of_frame);         // blendshape weights, muscle activations, jaw
///     auto report = hr.step(exec::omp);           // ConvergenceError names the residual
///     Points<> skin = hr.surface(exec::omp);      // M×3, the output surface
///
/// The warm start follows the jaw: the free vertices are carried from the last frame's jaw angle
/// to this frame's by the hinge rotation weighted with a harmonic field that is 1 on the jaw bone
/// and 0 on the cranium (mesh/harmonic_field.hpp), so flesh near the jaw moves with it instead of
/// being torn from it by the bone's Dirichlet step. Of that start and the same carried
/// extrapolation of the last two frames, the one of lower total energy starts Newton.
///
/// A frame whose Newton solve fails is retried by continuation: from the last solved state the
/// controls are walked to the frame's in 2, 4, … 2^substep_levels equal steps (every control is
/// linear in the forces, so the substeps are the frame's load split into parts). A fast
/// performance (a controls file jumping between keys) thus costs more iterations, not a failure;
/// ConvergenceError only when the finest split fails too.

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../../discretize/embedding.hpp"
#include "../../mesh/harmonic_field.hpp"
#include "../../mesh/topology.hpp"
#include "../../physics/dirichlet_boundary.hpp"
#include "../../physics/elastic_energy.hpp"
#include "../../physics/forces/embedded_springs.hpp"
#include "../../physics/forces/obstacle_contact.hpp"
#include "../../physics/forces/self_contact.hpp"
#include "../../physics/linear_solvers/linear_solvers.hpp"
#include "../../physics/linear_solvers/multigrid.hpp"
#include "../../physics/materials/mooney_rivlin.hpp"
#include "../../physics/materials/teran_muscle.hpp"
#include "../../physics/quasistatic.hpp"
#include "../../neighbors/surface_distance.hpp"
#include "face_model.hpp"

namespace simsr::scenario {

/// Which mesh a FaceSimulator runs on.
enum class FaceResolution { low, high };

inline const char* resolution_name(FaceResolution r) { return r == FaceResolution::high ? "HR" : "LR"; }

/// One frame's controls: the kit's blendshape weights, the muscles' activations, the jaw angle.
struct FaceControls {
  VecX<> blendshapes;  ///< one weight per expression of the model (FaceModel::expression_names)
  VecX<> muscles;      ///< one activation in [0, 1] per FaceModel::muscles; empty: from the blendshapes (muscle_activations)
  double jaw = 0;      ///< rad, the jaw's rotation from the neutral about the hinge (≥ 0 opens)
};

/// All controls at rest: no blendshape, muscles from the blendshapes (none), the jaw closed.
inline FaceControls neutral_controls(const FaceModel& face) {
  FaceControls c;
  c.blendshapes = VecX<>::Zero(face.num_expressions());
  return c;
}

/// Material and force parameters, per unit volume or area (SI).
struct FaceSimulationOptions {
  static physics::NewtonOptions default_newton() {
    physics::NewtonOptions o;
    o.relative_tolerance = 1e-5;
    // A floor in newtons: the relative test's reference is the largest force seen in the solve,
    // so a frame that starts at equilibrium (the same controls again) sees a reference of ~1 N
    // and chases the lip contact's non-smooth residual for 30+ iterations (measured on the coarse
    // model: ‖g‖ 1.0 → 0.05 in 14 iterations, 0.01 in 32; the positions moved by at most 0.6 mm,
    // 1.4 µm on average, from the first frame's ‖g‖ = 17 to full convergence).
    o.absolute_tolerance = 0.1;
    o.max_iterations = 30;  // ordinary frames take 2–7; beyond 30 continuation is cheaper
    // Eisenstat–Walker: a frame's first systems are solved loosely (issue #17 item 1; bench_face's
    // BM_face_performance, 120 frames at the paper's LR size: 268 PCG iterations against 1,062
    // with PCG to 1e-4 in every system, 0.79× the time, as close to tightly converged frames as
    // the tolerance allows). The HR mesh keeps `hr_forcing` below.
    o.forcing = physics::NewtonOptions::Forcing::adaptive;
    return o;
  }
  /// The V-cycle's defaults (issue #17 item 1, the same measurement: 1,062 PCG iterations over the
  /// performance against 1,877 with one Jacobi sweep and the levels rebuilt at every setup, the
  /// same frames to 0.7 µm): a Chebyshev smoother of degree 2, the coarse levels kept over 4
  /// setups of a frame (a frame starts with fresh ones: FaceSimulator::advance), single-precision
  /// 3×3-block levels (PCG itself stays in double). The Chebyshev interval comes from the Lanczos
  /// estimate (MultigridOptions::spectrum, automatic): with the power method's, a large frame on
  /// the HR mesh (the coarse model, neutral to a 0.6 smile) under-estimated coarse levels 2–2.7×,
  /// the V-cycle lost definiteness and one Newton system ran PCG for minutes.
  static physics::MultigridOptions default_multigrid() {
    physics::MultigridOptions m;
    m.smoother = physics::MultigridOptions::Smoother::chebyshev;
    m.chebyshev_degree = 2;
    m.coarse_refresh_every = 4;
    m.storage = physics::MultigridOptions::Storage::block_single;
    return m;
  }
  double mu10 = 4e3;            ///< Pa, Mooney–Rivlin (soft tissue: a few kPa)
  double mu01 = 1e3;            ///< Pa
  double kappa = 1e5;           ///< Pa, volume penalty (ν ≈ 0.45)
  /// J0 of the Mooney–Rivlin extension below which ln J and the J powers continue linearly
  /// (materials/isotropic.hpp): smaller resists inversion harder.
  double inversion_threshold = 0.1;
  /// Pa, the muscles' maximum isometric stress σ_max (Teran 2003's 3e5 Pa is for limb muscle
  /// against stiffer flesh; scaled here to the soft flesh above).
  double muscle_max_stress = 2e4;
  double track_stiffness = 3e6; ///< N/m³: track spring stiffness per unit skin area
  double contact_stiffness = 2e9;  ///< N/m³: lip contact stiffness per unit area (HR)
  double contact_thickness = 5e-4; ///< m: d̂, the lips' contact distance (HR)
  /// A lip vertex's d̂ is at most this fraction of its rest distance to the other lip: near the
  /// corners of the mouth, where the lips nearly touch at rest, contact is off at rest and
  /// still keeps the lips from crossing (make_contact).
  double contact_rest_fraction = 0.5;
  physics::NewtonOptions newton = default_newton();
  /// Newton's forcing on the HR mesh, in place of newton.forcing (which the LR mesh uses): fixed
  /// (each system to linear.tolerance). With the lip contact, Eisenstat–Walker's loose systems
  /// cost Newton steps: the HR tolerance case of tests/scenario/test_face_datagen.cpp (the coarse
  /// model's 4 HR frames), run with each forcing, took 24 Newton steps against 12 and ended 41 µm
  /// from tightly solved frames against 25.
  physics::NewtonOptions::Forcing hr_forcing = physics::NewtonOptions::Forcing::fixed;
  /// Also try the linear extrapolation of the last two frames (2x₁ − x₀, carried by the jaw) as
  /// the warm start, taken when its total energy is lower than the last frame's: along a smooth
  /// performance it halves the Newton iterations; where the motion turns, the last frame wins.
  bool extrapolate = true;
  /// Carry the warm start with the jaw (file comment); false starts from the last frame as it
  /// was, with only the bones moved (the ablation: the first Newton step then has to pull the
  /// flesh after the jaw, several iterations of a large residual).
  bool carry_with_jaw = true;
  /// A failed frame is retried in 2, 4, … 2^substep_levels steps of its controls (file comment).
  Index substep_levels = 3;
  physics::ConjugateGradientOptions linear{.tolerance = 1e-4};
  /// The V-cycle's options where Linear is PCG with the lattice multigrid (the default).
  physics::MultigridOptions multigrid = default_multigrid();
  /// Its levels (physics::lattice_hierarchy). The default coarsens each level to at most 1/8 of
  /// the one before (LatticeHierarchyOptions::coarsening, 2026-12-07); `coarsening = 0` gives the
  /// earlier hierarchy, the cell size doubling per level.
  physics::LatticeHierarchyOptions hierarchy{};
};

/// A quasistatic face simulator on one mesh of a FaceModel (see the file comment). Linear: the
/// Newton systems' solver (default PCG with the lattice multigrid).
template <class Linear = physics::ConjugateGradient<physics::Multigrid<>>>
class FaceSimulator {
 public:
  template <exec::HostPolicy P>
  FaceSimulator(P policy, const FaceModel& face, FaceResolution resolution, FaceSimulationOptions options = {})
      : face_(&face),
        res_(resolution),
        opt_(std::move(options)),
        mesh_(resolution == FaceResolution::high ? face.hr : face.lr),
        elastic_(part_of_mesh(face, false), physics::MooneyRivlin<>(opt_.mu10, opt_.mu01, opt_.kappa, opt_.inversion_threshold)),
        muscle_(part_of_mesh(face, true), physics::TeranMuscle<>(physics::MooneyRivlin<>(opt_.mu10, opt_.mu01, opt_.kappa, opt_.inversion_threshold), opt_.muscle_max_stress),
                fibres_),
        newton_(mesh_.num_vertices(), mesh_.T, newton_options(opt_, resolution), physics::make_linear_solver<Linear>(policy, mesh_, opt_.linear, opt_.hierarchy, opt_.multigrid)),
        tracks_(make_tracks()) {
    const bool high = resolution == FaceResolution::high;
    bone_ = high ? face.hr_bone : face.lr_bone;
    bone_jaw_ = high ? face.hr_bone_jaw : face.lr_bone_jaw;
    bone_rest_.resize(bone_.size(), 3);
    for (Index i = 0; i < bone_.size(); ++i) bone_rest_.row(i) = mesh_.V.row(bone_[i]);
    jaw_field_ = harmonic_field(policy, vertex_adjacency(mesh_.T, mesh_.num_vertices()), bone_, bone_jaw_);
    if (high) make_contact(policy);
    x_ = mesh_.V;
    FaceControls rest = neutral_controls(face);
    rest.jaw = face.rest_jaw_angle;
    set_controls(rest);
    solved_controls_ = rest;
  }

  FaceResolution resolution() const { return res_; }
  const TetMesh<>& mesh() const { return mesh_; }
  const Points<>& positions() const { return x_; }
  /// Starts the next solve from these positions (a resumed run's last frame), taken as solved
  /// under the current controls (continuation and the warm start walk from them).
  void set_positions(const Points<>& x) {
    if (x.rows() != mesh_.num_vertices() || x.cols() != 3) throw ShapeError("FaceSimulator::set_positions", {mesh_.num_vertices(), 3}, {x.rows(), x.cols()});
    if (!x.allFinite()) throw ArgumentError("FaceSimulator::set_positions: non-finite positions");
    x_ = x;
    have_previous_ = false;
    x_is_solution_ = true;
    solved_controls_ = controls_;
  }
  /// As set_positions, with the frame before it too, solved under `before_controls` (the warm
  /// start extrapolates from both): a resumed run repeats the uninterrupted one's frames bitwise.
  void set_positions(const Points<>& before, const FaceControls& before_controls, const Points<>& x) {
    set_positions(before);
    set_positions(x);
    previous_ = before;
    previous_jaw_ = before_controls.jaw;
    if (!std::isfinite(previous_jaw_)) throw ArgumentError("FaceSimulator::set_positions: non-finite jaw angle of the frame before");
    have_previous_ = true;
  }
  void reset() {
    x_ = mesh_.V;
    have_previous_ = x_is_solution_ = false;
  }

  /// Sets the spring targets, the muscles' activations and the bones' positions for the next step.
  void set_controls(const FaceControls& c) {
    const Index E = face_->num_expressions();
    if (c.blendshapes.size() != E) throw ShapeError("FaceSimulator::set_controls: blendshape weights", {E, 1}, {c.blendshapes.size(), 1});
    if (!c.blendshapes.allFinite() || !std::isfinite(c.jaw)) throw ArgumentError("FaceSimulator::set_controls: non-finite control");
    const Index nm = Index(face_->muscles.size());
    const VecX<> act = activations_of(c);
    if (act.size() != nm) throw ShapeError("FaceSimulator::set_controls: muscle activations", {nm, 1}, {act.size(), 1});
    for (Index k = 0; k < nm; ++k)
      if (!(act[k] >= 0 && act[k] <= 1)) throw ArgumentError("FaceSimulator::set_controls: activation of muscle '" + face_->muscles[std::size_t(k)].spec.name + "' is " + std::to_string(act[k]) + ", not in [0, 1]");
    for (std::size_t t = 0; t < fibres_.size(); ++t) fibres_[t].activation = act[muscle_of_tet_[t]] * muscle_share_[t];
    muscle_.set_elements(fibres_);
    const Index M = face_->surface.num_vertices();
    VecX<> flat = face_->deltas.transpose() * c.blendshapes;
    Points<> y = face_->neutral + Eigen::Map<const Points<>>(flat.data(), M, 3);
    tracks_.set_targets(y);
    // bones: linear blend of fixed and hinged
    const double delta = c.jaw - face_->rest_jaw_angle;
    const Mat3<> R = Eigen::AngleAxisd(delta, face_->hinge.axis.normalized()).toRotationMatrix();
    const Vec3<> p = face_->hinge.point;
    boundary_.vertices = bone_;
    boundary_.targets.resize(bone_.size(), 3);
    for (Index i = 0; i < bone_.size(); ++i) {
      const Vec3<> x = bone_rest_.row(i).transpose();
      const Vec3<> jawed = R * (x - p) + p;
      boundary_.targets.row(i) = ((1 - bone_jaw_[i]) * x + bone_jaw_[i] * jawed).transpose();
    }
    controls_ = c;
  }

  /// One quasistatic frame from the current positions; ConvergenceError when Newton fails.
  template <exec::HostPolicy P>
  physics::NewtonReport step(P policy) {
    return advance([&](Points<>& x) { return with_terms([&](const auto&... t) { return newton_.solve(policy, x, boundary_, t...); }); },
                   [&](const Points<>& x) { return with_terms([&](const auto&... t) { return (0.0 + ... + double(t.energy(policy, x))); }); });
  }

  /// As step, for a frame far from the last solved one (a chunk's first lead-in frame, reached
  /// from the neutral): the continuation's substeps from the start, without the direct Newton
  /// solve that would spend its whole iteration cap first (measured: a mid-performance frame of
  /// amazement from the neutral, HR, 30 failed iterations and then 12 in 2 substeps).
  template <exec::HostPolicy P>
  physics::NewtonReport step_from_afar(P policy) {
    return advance([&](Points<>& x) { return with_terms([&](const auto&... t) { return newton_.solve(policy, x, boundary_, t...); }); },
                   [&](const Points<>& x) { return with_terms([&](const auto&... t) { return (0.0 + ... + double(t.energy(policy, x))); }); },
                   false);
  }

  /// As step, with one more energy term for this frame (the §5.3 "unseen forces": a spring, an
  /// obstacle).
  template <exec::HostPolicy P, class Extra>
  physics::NewtonReport step_with(P policy, const Extra& extra) {
    return advance([&](Points<>& x) { return with_terms([&](const auto&... t) { return newton_.solve(policy, x, boundary_, t...); }, extra); },
                   [&](const Points<>& x) { return with_terms([&](const auto&... t) { return (0.0 + ... + double(t.energy(policy, x))); }, extra); });
  }

  /// The jaw weight of every vertex: 1 on the jaw bone, 0 on the cranium, harmonic in between
  /// (the warm start's skinning weights).
  const VecX<>& jaw_field() const { return jaw_field_; }

  /// The output surface (M×3) at the current positions.
  template <exec::HostPolicy P>
  Points<> surface(P policy) const {
    if (res_ == FaceResolution::high) {
      Points<> s(face_->surface_hr_vertex.size(), 3);
      for (Index i = 0; i < s.rows(); ++i) s.row(i) = x_.row(face_->surface_hr_vertex[i]);
      return s;
    }
    return deform(policy, face_->surface_in_lr, mesh_.T, x_);
  }

  /// Inverted tets at the current positions.
  template <exec::HostPolicy P>
  Index count_inverted(P policy) const {
    return elastic_.count_inverted(policy, x_) + muscle_.count_inverted(policy, x_);
  }

  const physics::EmbeddedSprings<>& tracks() const { return tracks_; }
  /// Each muscle's active volume at rest (m³): Σ over its tets of volume × share inside it.
  std::vector<double> muscle_volumes() const {
    std::vector<double> v(face_->muscles.size(), 0.0);
    const auto& vol = muscle_.rest().volume;
    for (std::size_t t = 0; t < muscle_of_tet_.size(); ++t) v[std::size_t(muscle_of_tet_[t])] += double(vol[Index(t)]) * muscle_share_[t];
    return v;
  }
  bool has_contact() const { return contact_.has_value(); }
  /// The two lip contact terms (upper vertices against lower triangles, and the reverse); HR only.
  const std::pair<physics::SelfContact<>, physics::SelfContact<>>& contact() const {
    if (!contact_) throw ArgumentError("FaceSimulator::contact: the LR simulator has no lip contact");
    return *contact_;
  }

 private:
  /// options.newton, with options.hr_forcing on the HR mesh.
  static physics::NewtonOptions newton_options(const FaceSimulationOptions& options, FaceResolution resolution) {
    physics::NewtonOptions o = options.newton;
    if (resolution == FaceResolution::high) o.forcing = options.hr_forcing;
    return o;
  }
  /// The flesh tets (muscle = false) or the muscle tets of the mesh, over all its vertices; the
  /// muscle tets' fibres go to fibres_, muscle_of_tet_ and muscle_share_ (called for the flesh first).
  TetMesh<> part_of_mesh(const FaceModel& face, bool muscle) {
    const TetMesh<>& m = res_ == FaceResolution::high ? face.hr : face.lr;
    if (!muscle) {
      // 11 points per tet (centroid, 4 towards the corners, 6 towards the edges): the share of
      // them inside a muscle scales its activation, so a coarse tet half in a thin muscle pulls
      // half as hard and the muscle's force per volume agrees across resolutions. An LR tet's
      // points count only inside the flesh (its pieces' HR tets): lattice tets reach past the
      // skin, and the lips' ring would otherwise pull with the air in the mouth.
      static constexpr int ns = 11;
      Eigen::Matrix<double, ns, 4> B;
      B.row(0).setConstant(0.25);
      for (int k = 0; k < 4; ++k) {
        B.row(1 + k).setConstant(0.1);
        B(1 + k, k) = 0.7;
      }
      static constexpr int edge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
      for (int e = 0; e < 6; ++e) {
        B.row(5 + e).setConstant(0.1);
        B(5 + e, edge[e][0]) = B(5 + e, edge[e][1]) = 0.4;
      }
      in_muscle_.assign(std::size_t(m.T.rows()), 0);
      std::vector<int> votes(face.muscles.size());
      std::vector<Vec3<>> dir(face.muscles.size());
      for (Index t = 0; t < m.T.rows(); ++t) {
        std::fill(votes.begin(), votes.end(), 0);
        std::fill(dir.begin(), dir.end(), Vec3<>::Zero());
        for (int q = 0; q < ns; ++q) {
          Vec3<> c = Vec3<>::Zero();
          for (int k = 0; k < 4; ++k) c += B(q, k) * m.V.row(m.T(t, k)).transpose();
          if (res_ == FaceResolution::low && !in_flesh(face, t, c)) continue;
          if (const auto f = muscle_fibre_at(face.muscles, c)) {
            ++votes[std::size_t(f->muscle)];
            // fibres are lines: align the sign before summing
            dir[std::size_t(f->muscle)] += dir[std::size_t(f->muscle)].dot(f->direction) < 0 ? Vec3<>(-f->direction) : f->direction;
          }
        }
        const auto best = std::max_element(votes.begin(), votes.end());
        if (best == votes.end() || *best == 0) continue;
        const std::size_t k = std::size_t(best - votes.begin());
        in_muscle_[std::size_t(t)] = 1;
        fibres_.push_back(physics::TeranMuscle<>::element(dir[k], 0.0));
        muscle_of_tet_.push_back(Index(k));
        muscle_share_.push_back(double(*best) / ns);
      }
    }
    std::vector<Index> rows;
    for (Index t = 0; t < m.T.rows(); ++t)
      if (bool(in_muscle_[std::size_t(t)]) == muscle) rows.push_back(t);
    TetMesh<> part{m.V, Tets(Index(rows.size()), 4)};
    for (std::size_t r = 0; r < rows.size(); ++r) part.T.row(Index(r)) = m.T.row(rows[r]);
    return part;
  }

  /// The muscle activations of c: given, or from its blendshapes.
  VecX<> activations_of(const FaceControls& c) const {
    return c.muscles.size() ? c.muscles : muscle_activations(face_->muscles, face_->expression_names, c.blendshapes);
  }

  /// Whether point c lies in one of LR tet t's pieces (HR tets, closed up to round-off).
  static bool in_flesh(const FaceModel& face, Index t, const Vec3<>& c) {
    const auto& split = face.lr_split;
    for (Index q = split.piece_offsets[std::size_t(t)]; q < split.piece_offsets[std::size_t(t) + 1]; ++q) {
      const Index e = split.piece_material[std::size_t(q)];
      const Vec3<> a = face.hr.V.row(face.hr.T(e, 0)).transpose();
      Mat3<> D;
      for (int k = 0; k < 3; ++k) D.col(k) = face.hr.V.row(face.hr.T(e, k + 1)).transpose() - a;
      const Vec3<> b = D.partialPivLu().solve(c - a);
      constexpr double eps = 1e-9;
      if (b.minCoeff() >= -eps && b.sum() <= 1 + eps) return true;
    }
    return false;
  }

  /// f(every energy term of this simulator, extra...).
  template <class F, class... Extra>
  decltype(auto) with_terms(F&& f, const Extra&... extra) {
    if (contact_) return f(elastic_, muscle_, tracks_, contact_->first, contact_->second, extra...);
    return f(elastic_, muscle_, tracks_, extra...);
  }

  /// x (solved with the jaw at angle `from`) carried to the jaw at `to`: every vertex rotated
  /// about the hinge by (to − from) × its jaw weight, the bones set to their targets.
  Points<> carried_by_jaw(const Points<>& x, double from, double to) const {
    Points<> y = x;
    const Mat3<> R = Eigen::AngleAxisd(to - from, face_->hinge.axis.normalized()).toRotationMatrix();
    const Vec3<> p = face_->hinge.point;
    if (opt_.carry_with_jaw && to != from)
      for (Index v = 0; v < y.rows(); ++v)
        if (const double w = jaw_field_[v]; w != 0) {
          const Vec3<> a = x.row(v).transpose();
          y.row(v) = (a + w * (R * (a - p) + p - a)).transpose();
        }
    for (Index i = 0; i < bone_.size(); ++i) y.row(bone_[i]) = boundary_.targets.row(i);
    return y;
  }

  /// Runs `solve` from the warm start (`direct`; else by continuation from the last solved state
  /// at once) and moves the frame history on.
  template <class Solve, class Energy>
  physics::NewtonReport advance(Solve&& solve, Energy&& energy, bool direct = true) {
    // a frame depends on x_, previous_, their jaw angles and the controls only (a resumed run
    // repeats it bitwise): the multigrid's warm eigenvalue estimate would carry the last
    // frame's history
    if constexpr (requires { newton_.linear_solver().preconditioner().forget_estimates(); })
      newton_.linear_solver().preconditioner().forget_estimates();
    const double jaw = solved_controls_.jaw;
    physics::NewtonReport r;
    if (direct) {
      start_ = carried_by_jaw(x_, jaw, controls_.jaw);
      if (opt_.extrapolate && have_previous_) {
        Points<> ahead = carried_by_jaw(2 * x_ - previous_, 2 * jaw - previous_jaw_, controls_.jaw);
        const double e = energy(ahead);
        if (std::isfinite(e) && !(e >= energy(start_))) start_.swap(ahead);  // lower, or the last frame's not finite
      }
      try {
        r = solve(start_);
      } catch (const ConvergenceError& failed) {
        r = continuation(solve, failed.iterations(), failed.residual());
      }
    } else {
      r = continuation(solve, 0, std::numeric_limits<double>::quiet_NaN());
    }
    previous_jaw_ = jaw;
    solved_controls_ = controls_;
    previous_.swap(x_);
    x_.swap(start_);
    have_previous_ = x_is_solution_;  // extrapolate only between two solved frames
    x_is_solution_ = true;
    return r;
  }

  /// The frame's controls reached from the last solved ones in 2^k equal steps, k = 1, 2, …
  /// substep_levels, after `spent` iterations of a failed direct solve that ended at `residual`;
  /// the result lands in start_. Rethrows (naming the levels) when all fail.
  template <class Solve>
  physics::NewtonReport continuation(Solve& solve, Index spent, double residual) {
    const FaceControls target = controls_;
    Index linear = 0;
    auto lerp = [&](double s) {
      FaceControls c;
      c.blendshapes = (1 - s) * solved_controls_.blendshapes + s * target.blendshapes;
      if (target.muscles.size() || solved_controls_.muscles.size())  // given on either side: interpolate the activations
        c.muscles = ((1 - s) * activations_of(solved_controls_) + s * activations_of(target)).cwiseMax(0.0).cwiseMin(1.0);  // clamp: round-off only
      c.jaw = (1 - s) * solved_controls_.jaw + s * target.jaw;
      return c;
    };
    for (Index level = 1; level <= opt_.substep_levels; ++level) {
      const Index n = Index(1) << level;
      Points<> x = x_;
      double jaw = solved_controls_.jaw;
      physics::NewtonReport r;
      bool ok = true;
      for (Index i = 1; i <= n && ok; ++i) {
        set_controls(i == n ? target : lerp(double(i) / double(n)));
        x = carried_by_jaw(x, jaw, controls_.jaw);
        jaw = controls_.jaw;
        try {
          r = solve(x);
          spent += r.iterations;
          linear += r.linear_iterations;
        } catch (const ConvergenceError& e) {
          spent += e.iterations();
          residual = e.residual();
          ok = false;
        }
      }
      if (ok) {
        set_controls(target);
        start_ = std::move(x);
        r.iterations = spent;
        r.linear_iterations = linear;
        return r;
      }
    }
    set_controls(target);
    throw ConvergenceError("face frame by continuation in up to " + std::to_string(Index(1) << opt_.substep_levels) + " substeps", spent, residual);
  }

  physics::EmbeddedSprings<> make_tracks() const {
    const VecX<> k = opt_.track_stiffness * face_->surface_area;
    if (res_ == FaceResolution::low)
      return physics::EmbeddedSprings<>(face_->surface_in_lr, mesh_.T, mesh_.num_vertices(), k, face_->surface.V);
    // HR: the skin vertices are mesh vertices (tetgen keeps the boundary)
    physics::EmbeddedSprings<> s = physics::vertex_springs(mesh_.V, face_->surface_hr_vertex, 0.0);
    s.set_stiffness(k);
    s.set_targets(face_->surface.V);
    return s;
  }

  /// Lip contact: vertices of one lip against triangles of the other, each vertex with its own d̂:
  /// contact_thickness, capped at contact_rest_fraction of its rest distance to the other lip.
  /// The kit's own neutral has the lips crossing near the corners of the mouth, where they lie
  /// 1–2.5 mm apart in the rest pose (86 upper and lower triangle pairs intersect at the
  /// blendshape targets of the closed jaw), so contact must act there. A uniform d̂ there presses the lips apart at rest; leaving out the vertices
  /// within 3 mm of the other lip at rest (the first build) let the tracks pull the closed-jaw
  /// frames through each other (114 intersecting pairs in every performance's first and last frame).
  template <class P>
  void make_contact(P policy) {
    if (!(opt_.contact_rest_fraction > 0 && opt_.contact_rest_fraction <= 1) || !(opt_.contact_thickness > 0) || !(opt_.contact_stiffness >= 0))
      throw ArgumentError("FaceSimulator: contact_rest_fraction must be in (0, 1], contact_thickness > 0 and contact_stiffness >= 0");
    const auto thickness = [&](const IndexVector& verts, const Tris& other) {
      VecX<> dhat = VecX<>::Constant(verts.size(), opt_.contact_thickness);
      if (other.rows() == 0 || verts.size() == 0) return dhat;
      const TriMesh<> o{mesh_.V, other};
      const neighbors::SurfaceDistance<> dist(o);
      Points<> at(verts.size(), 3);
      for (Index i = 0; i < verts.size(); ++i) at.row(i) = mesh_.V.row(verts[i]);
      const VecX<> d = dist.distances(policy, at);
      for (Index i = 0; i < verts.size(); ++i) {
        if (!(d[i] > 0))
          throw ArgumentError("FaceSimulator: lip vertex " + std::to_string(verts[i]) + " lies on the other lip at rest (distance " + std::to_string(d[i]) +
                              "): the lips must be apart in the rest pose");
        dhat[i] = std::min(dhat[i], opt_.contact_rest_fraction * d[i]);
      }
      return dhat;
    };
    const double k = opt_.contact_stiffness * face_->surface_area.mean();
    contact_.emplace(physics::SelfContact<>(face_->lip_upper_vertices, face_->lip_lower_triangles, mesh_.num_vertices(), k,
                                            thickness(face_->lip_upper_vertices, face_->lip_lower_triangles)),
                     physics::SelfContact<>(face_->lip_lower_vertices, face_->lip_upper_triangles, mesh_.num_vertices(), k,
                                            thickness(face_->lip_lower_vertices, face_->lip_upper_triangles)));
  }

  const FaceModel* face_;
  FaceResolution res_;
  FaceSimulationOptions opt_;
  TetMesh<> mesh_;
  std::vector<char> in_muscle_;
  std::vector<physics::MuscleFibre<>> fibres_;
  std::vector<Index> muscle_of_tet_;
  std::vector<double> muscle_share_;  ///< share of the tet's sample points inside its muscle
  physics::ElasticEnergy<physics::MooneyRivlin<>> elastic_;
  physics::ElasticEnergy<physics::TeranMuscle<>> muscle_;
  physics::QuasistaticSolver<Linear> newton_;
  physics::EmbeddedSprings<> tracks_;
  std::optional<std::pair<physics::SelfContact<>, physics::SelfContact<>>> contact_;
  IndexVector bone_;
  VecX<> bone_jaw_;
  Points<> bone_rest_;
  physics::DirichletBoundary<> boundary_;
  FaceControls controls_;
  VecX<> jaw_field_;  ///< per vertex: 1 on the jaw bone, 0 on the cranium, harmonic between
  Points<> x_, previous_, start_;
  double previous_jaw_ = 0;  ///< the jaw angle previous_ was solved under
  bool have_previous_ = false, x_is_solution_ = false;
  FaceControls solved_controls_;  ///< the controls x_ was solved under
};

}  // namespace simsr::scenario
