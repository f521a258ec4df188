#pragma once
/// \file
/// A cloth simulator on a triangle surface (the data of Chen et al. 2023, §3 of the supplement,
/// issue #14): the coarse and the fine cloth are simulated separately with the same parameters
/// and no constraint between them. Each frame is `substeps` backward-Euler steps, each at most a
/// few Newton iterations with line search (the default) or a Newton solve to convergence
/// (physics::QuasistaticSolver; ClothStepping) of
///
///     ARAP membrane (TriangleMembrane) + bending (SurfaceBending) + gravity (lumped areal masses)
///     + inertia (ImplicitInertia: α = 1, γ = 1, damping β) + wind (VertexForces from the last
///     step's velocities, shell::wind_forces) + penalty contact with one rigid obstacle, at the
///     vertices and at 4 points inside each triangle (EmbeddedObstacleContact)
///
/// (without the triangles' points a sphere narrower than a coarse triangle would pass between
/// its vertices: 25 cm cells at the ×256 scale study, 12.5 cm at the paper's SHEET)
/// with pinned vertices held at their rest positions. Every stiffness is per area, so the two
/// resolutions model the same cloth: k_membrane A_t per triangle, contact κ A_i per vertex.
///
///     shell::ClothSimulator<physics::Capsule<>> sim(rest, pins, physics::Capsule<>(a, b, 0.1), {}, {});
///     sim.advance(exec::omp, [&](physics::Capsule<>& pole, double t) { pole.set_ends(a + t * v, b + t * v); });

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <utility>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../mesh/tri_mesh.hpp"
#include "../mesh/vertex_areas.hpp"
#include "../physics/dirichlet_boundary.hpp"
#include "../physics/forces/gravity.hpp"
#include "../physics/forces/implicit_inertia.hpp"
#include "../physics/forces/embedded_obstacle_contact.hpp"
#include "../physics/forces/obstacle_contact.hpp"
#include "../physics/forces/surface_bending.hpp"
#include "../physics/forces/triangle_membrane.hpp"
#include "../physics/forces/vertex_forces.hpp"
#include "../physics/quasistatic.hpp"
#include "wind.hpp"

namespace simsr::shell {

/// The cloth, the same at every resolution.
struct ClothMaterial {
  double areal_density = 0.2;  ///< kg/m² (a knit: ARCSim's gray interlock weighs ~0.2)
  double stretch = 40;         ///< TriangleMembrane k (N/m): k Σ_t A_t ‖F_t − R_t‖²
  double bending = 2e-5;       ///< SurfaceBending k (N·m)
};

/// How each backward-Euler step is solved.
///
/// `inexact` (the default): at most 3 Newton iterations from the prediction (the budget of
/// cloth_newton_options), on the projected (PSD) Hessian, each with a line search on the step's
/// energy; fewer where the gradient falls to 10⁻⁶ of its scale, and the iterate taken when the
/// budget is spent (physics::NewtonOptions::accept_at_max_iterations).
/// One iteration is Baraff & Witkin 1998's linearized implicit Euler, ARCSim's scheme (the
/// paper's data). `converged`: Newton to a relative gradient of 10⁻⁶ (at most 30 iterations),
/// the Hessian `regularized` (exact, shifted where a folding cloth makes it indefinite).
///
/// Why 3 iterations at 8 steps per frame: measured on DISK's fine cloth (7,057 vertices) in
/// 5.7 m/s wind, 3 frames from a checkpoint, against Newton converged at 8 steps per frame: 3
/// iterations 0.13 / 0.19 / 0.24 mm RMS apart after 1 / 2 / 3 frames at 7–8 s per fine frame;
/// 1 iteration 0.8 / 2.2 / 3.5 mm at 4.5–5.8 s; converged at 2 steps per frame (the earlier
/// default) 1.3 / 2.5 / 4.2 mm at 31–83 s; converged at 8 steps 29–35 s (README, "Thin shells").
/// Not cheaper everywhere: on bench_shell's SHEET pole, where converged Newton needs 8
/// iterations per step, the budget's 24 per frame cost 1.5× the earlier default's 16.
enum class ClothStepping { inexact, converged };

/// Newton's options for one step of `stepping` (see ClothStepping); `iterations` the budget
/// (inexact) or the cap (converged), 0 for the stepping's default (3 / 30).
inline physics::NewtonOptions cloth_newton_options(ClothStepping stepping, Index iterations = 0) {
  if (iterations < 0) throw ArgumentError("cloth steps: Newton iterations must be >= 0 (0: the default), got " + std::to_string(iterations));
  if (stepping == ClothStepping::converged)
    return {.relative_tolerance = 1e-6,
            .max_iterations = iterations > 0 ? iterations : 30,
            .hessian = physics::NewtonOptions::Hessian::regularized,
            .progress = {}};
  return {.relative_tolerance = 1e-6,
          .max_iterations = iterations > 0 ? iterations : 3,
          .accept_at_max_iterations = true,
          .hessian = physics::NewtonOptions::Hessian::projected,
          .progress = {}};
}

/// "inexact" or "converged" (`simsr datagen|demo --stepping`); ArgumentError naming the others.
inline ClothStepping parse_cloth_stepping(const std::string& name) {
  if (name == "inexact") return ClothStepping::inexact;
  if (name == "converged") return ClothStepping::converged;
  throw ArgumentError("cloth steps: unknown '" + name + "' (inexact: at most a few Newton iterations per backward-Euler step; converged: Newton to 1e-6)");
}

/// Time stepping, gravity and contact.
struct ClothOptions {
  double frame_time = 1.0 / 30;  ///< s per frame
  Index substeps = 8;            ///< backward-Euler steps per frame
  double damping = 0.02;         ///< ImplicitInertia β (s): velocity-proportional damping
  Vec3<> gravity{0, 0, -9.81};   ///< m/s²
  double contact_stiffness = 2e6;  ///< κ (N/m³): vertex i's penalty stiffness is κ A_i, a triangle point's κ A_t / 4
  /// The depth (m) over which the contact stiffness ramps up from 0 (physics::ObstacleContact::set_onset):
  /// 0 is the C¹ quadratic penalty, > 0 a C² one.
  double contact_onset = 0;
  /// Newton's options for each step: ClothStepping's inexact steps by default
  /// (cloth_newton_options(ClothStepping::converged) for Newton to convergence).
  physics::NewtonOptions newton = cloth_newton_options(ClothStepping::inexact);
  /// A step whose Newton solve fails (not converged where that is asked, or a line search that
  /// finds no decrease) is taken as two half steps, recursively, at most this deep (1/16 of a
  /// step at 4); beyond it the ConvergenceError is thrown.
  Index max_halvings = 4;
};

/// `o` itself; ArgumentError naming the first option out of range (the simulator's check, which
/// generate_cloth_data also runs before it writes anything).
inline ClothOptions checked_cloth_options(ClothOptions o) {
  if (!(o.frame_time > 0) || !std::isfinite(o.frame_time)) throw ArgumentError("ClothSimulator: frame time must be finite and > 0");
  if (o.substeps < 1) throw ArgumentError("ClothSimulator: substeps must be >= 1, got " + std::to_string(o.substeps));
  if (o.max_halvings < 0) throw ArgumentError("ClothSimulator: max_halvings must be >= 0, got " + std::to_string(o.max_halvings));
  if (!(o.contact_stiffness >= 0) || !std::isfinite(o.contact_stiffness))
    throw ArgumentError("ClothSimulator: contact stiffness must be finite and >= 0");
  if (!(o.contact_onset >= 0) || !std::isfinite(o.contact_onset)) throw ArgumentError("ClothSimulator: contact onset must be finite and >= 0");
  return o;
}

/// One frame's figures.
struct ClothFrameReport {
  Index newton_iterations = 0;  ///< over the frame's substeps (failed solves included)
  Index halvings = 0;           ///< steps split in two after a failed solve
  double deepest = 0;           ///< the most negative obstacle distance of a vertex or triangle point at the frame's end (m; 0 if none inside)
};

/// The simulator (see the file comment); O is the obstacle (physics::Obstacle), Linear the Newton
/// step's linear solver (physics::LinearSolver): SparseCholesky (Eigen's simplicial LDLᵀ, the
/// default) or, built with CHOLMOD, physics::CholmodCholesky (supernodal; the same steps to
/// round-off, 2.7× faster at the paper's 4,225 fine vertices, where the factorization is nearly
/// all of a step: benchmarks/bench_shell.cpp). A Linear that is not a LinearSolver stops the build
/// with QuasistaticSolver's one sentence.
template <physics::Obstacle O, class Linear = physics::SparseCholesky<>>
class ClothSimulator {
 public:
  /// `rest` the cloth at rest (its start), `pinned` the vertices held there. ArgumentError for a
  /// bad material or option (checked by the terms too), MeshError for a bad surface or pin.
  ClothSimulator(TriMesh<> rest, IndexVector pinned, O obstacle, ClothMaterial material = {}, ClothOptions options = {})
      : rest_(std::move(rest)),
        options_(checked_cloth_options(options)),
        areas_(voronoi_areas(rest_.V, rest_.F)),
        membrane_(rest_.V.rows(), rest_.V, rest_.F, material.stretch),
        bending_(rest_.V.rows(), rest_.V, rest_.F, material.bending),
        gravity_(VecX<>(material.areal_density * areas_), options_.gravity),
        inertia_(VecX<>(material.areal_density * areas_), rest_.V,
                 {.h = options_.frame_time / double(options_.substeps), .alpha = 1, .beta = options_.damping, .gamma = 1}),
        wind_(rest_.V.rows()),
        contact_(obstacle, all_vertices(rest_.V.rows()), rest_.V.rows(), VecX<>(options_.contact_stiffness * areas_)),
        face_contact_(make_face_contact(std::move(obstacle), rest_, options_.contact_stiffness)),
        boundary_{std::move(pinned), Points<>()},
        solver_(rest_.V.rows(), Tets(0, 4), options_.newton),
        x_(rest_.V),
        previous_(rest_.V) {
    if (!(material.areal_density > 0) || !std::isfinite(material.areal_density))
      throw ArgumentError("ClothSimulator: areal density must be finite and > 0, got " + std::to_string(material.areal_density));
    for (Index k = 0; k < boundary_.vertices.size(); ++k)
      if (boundary_.vertices[k] < 0 || boundary_.vertices[k] >= rest_.V.rows())
        throw MeshError("pinned vertex", k, "ClothSimulator: vertex id " + std::to_string(boundary_.vertices[k]) + " outside [0, " +
                                                std::to_string(rest_.V.rows()) + ")");
    boundary_.targets = rest_.V(boundary_.vertices, Eigen::all);
    contact_.set_onset(options_.contact_onset);
    face_contact_.set_onset(options_.contact_onset);
    last_step_ = step_time();
  }

  const TriMesh<>& rest() const { return rest_; }
  const ClothOptions& options() const { return options_; }
  const IndexVector& pinned() const { return boundary_.vertices; }
  const Points<>& positions() const { return x_; }
  /// Velocities over the last step (m/s).
  Points<> velocities() const { return (x_ - previous_) / last_step_; }
  /// The last step's length (s): the step, or a fraction 1/2^k of it after halvings.
  double last_step() const { return last_step_; }
  /// Seconds since the start: steps × the step (a product, not a running sum, so a resumed run
  /// places its obstacle at the same instants).
  double time() const { return double(steps_) * step_time(); }
  Index steps() const { return steps_; }
  const O& obstacle() const { return contact_.obstacle(); }
  void set_air(const Air& air) { air_ = air; }
  const Air& air() const { return air_; }

  /// Restores a state: positions x after a step of `last_step` seconds from `previous`, `steps`
  /// steps (substeps) from the start (a checkpoint). The next frame continues bitwise as the run
  /// that saved it. ShapeError for another vertex count, ArgumentError for a non-finite position,
  /// steps < 0 or a last step not in (0, step].
  void set_state(const Points<>& x, const Points<>& previous, Index steps, double last_step) {
    for (const Points<>* p : {&x, &previous})
      if (p->rows() != x_.rows() || p->cols() != 3)
        throw ShapeError("ClothSimulator::set_state: positions", {x_.rows(), 3}, {p->rows(), p->cols()});
    if (!x.allFinite() || !previous.allFinite()) throw ArgumentError("ClothSimulator::set_state: a non-finite position");
    if (steps < 0) throw ArgumentError("ClothSimulator::set_state: steps must be >= 0, got " + std::to_string(steps));
    if (!(last_step > 0) || !(last_step <= step_time()))
      throw ArgumentError("ClothSimulator::set_state: the last step must be in (0, " + std::to_string(step_time()) + "] s, got " + std::to_string(last_step));
    inertia_.reset(previous);
    inertia_.advance(x);
    x_ = x;
    previous_ = previous;
    steps_ = steps;
    last_step_ = last_step;
  }
  const Points<>& previous_positions() const { return previous_; }

  /// One frame: `substeps` steps; before each, move(obstacle, t) places the obstacle at the step's
  /// end time t (s since the start). A failed Newton solve halves the step (ClothOptions::
  /// max_halvings; the momentum carried over scaled to the shorter step); a ConvergenceError
  /// only where that fails too.
  template <exec::HostPolicy P>
  ClothFrameReport advance(P policy, const std::function<void(O&, double)>& move = {}) {
    ClothFrameReport report;
    for (Index s = 0; s < options_.substeps; ++s) {
      step_piece(policy, move, double(steps_), 1.0, 0, report);
      ++steps_;
    }
    const O& o = contact_.obstacle();
    for (Index i = 0; i < x_.rows(); ++i) report.deepest = std::min(report.deepest, o.distance(Vec3<>(x_.row(i).transpose())));
    for (Index f = 0; f < rest_.F.rows(); ++f)
      for (int k = 0; k < 4; ++k) {
        Vec3<> p = Vec3<>::Zero();
        for (int c = 0; c < 3; ++c) p += face_point_weight(k, c) * x_.row(rest_.F(f, c)).transpose();
        report.deepest = std::min(report.deepest, o.distance(p));
      }
    return report;
  }

 private:
  double step_time() const { return options_.frame_time / double(options_.substeps); }
  /// The step from `start` (in steps) over `fraction` of a step; halved on a failed solve.
  template <class P>
  void step_piece(P policy, const std::function<void(O&, double)>& move, double start, double fraction, Index depth, ClothFrameReport& report) {
    const double h = fraction * step_time();
    if (move) {
      move(contact_.obstacle(), (start + fraction) * step_time());
      face_contact_.obstacle() = contact_.obstacle();
    }
    // the step's buffers live in the simulator: a frame allocates nothing of its own here
    velocity_ = (x_ - previous_) / last_step_;
    wind_forces(policy, x_, velocity_, rest_.F, air_, forces_);
    wind_.set_forces(forces_);
    // backward Euler over h from x_n with velocity (x_n − x_{n−1})/h_last: the prediction
    // x_n + (h/h_last)(x_n − x_{n−1})
    inertia_.set_parameters({.h = h, .alpha = 1, .beta = options_.damping, .gamma = h / last_step_});
    trial_ = x_;
    physics::NewtonReport r;
    try {
      r = solver_.solve(policy, trial_, boundary_, membrane_, bending_, gravity_, inertia_, wind_, contact_, face_contact_);
    } catch (const ConvergenceError& e) {
      report.newton_iterations += e.iterations();
      if (depth >= options_.max_halvings) throw;
      ++report.halvings;
      step_piece(policy, move, start, fraction / 2, depth + 1, report);
      step_piece(policy, move, start + fraction / 2, fraction / 2, depth + 1, report);
      return;
    }
    report.newton_iterations += r.iterations;
    inertia_.advance(trial_);
    previous_.swap(x_);
    x_.swap(trial_);
    last_step_ = h;
  }
  /// Barycentric weight of corner c at a triangle's point k: the centroid (k = 0) and the points
  /// halfway from it to each corner (k = 1, 2, 3: 2/3 at that corner, 1/6 at the others).
  static double face_point_weight(int k, int c) { return k == 0 ? 1.0 / 3 : (c == k - 1 ? 2.0 / 3 : 1.0 / 6); }
  static physics::EmbeddedObstacleContact<O> make_face_contact(O obstacle, const TriMesh<>& rest, double kappa) {
    const Index nf = rest.F.rows();
    typename physics::EmbeddedObstacleContact<O>::Anchors anchors(4 * nf, 4);
    typename physics::EmbeddedObstacleContact<O>::Weights weights(4 * nf, 4);
    VecX<> k(4 * nf);
    for (Index f = 0; f < nf; ++f) {
      const Vec3<> a = rest.V.row(rest.F(f, 0)), b = rest.V.row(rest.F(f, 1)), c = rest.V.row(rest.F(f, 2));
      const double area = 0.5 * (b - a).cross(c - a).norm();
      for (int q = 0; q < 4; ++q) {
        const Index row = 4 * f + q;
        anchors.row(row) << rest.F(f, 0), rest.F(f, 1), rest.F(f, 2), rest.F(f, 0);  // the 4th: weight 0
        weights.row(row) << face_point_weight(q, 0), face_point_weight(q, 1), face_point_weight(q, 2), 0.0;
        k[row] = kappa * area / 4;
      }
    }
    return physics::EmbeddedObstacleContact<O>(std::move(obstacle), std::move(anchors), std::move(weights), rest.V.rows(), std::move(k));
  }
  static IndexVector all_vertices(Index n) {
    IndexVector v(n);
    for (Index i = 0; i < n; ++i) v[i] = VIndex(i);
    return v;
  }

  TriMesh<> rest_;
  ClothOptions options_;
  VecX<> areas_;
  physics::TriangleMembrane<> membrane_;
  physics::SurfaceBending<> bending_;
  physics::Gravity<> gravity_;
  physics::ImplicitInertia<> inertia_;
  physics::VertexForces<> wind_;
  physics::ObstacleContact<O> contact_;
  physics::EmbeddedObstacleContact<O> face_contact_;
  physics::DirichletBoundary<> boundary_;
  physics::QuasistaticSolver<Linear> solver_;
  Air air_;
  Points<> x_, previous_;
  Points<> velocity_, forces_, trial_;  ///< per-step buffers (see step_piece)
  Index steps_ = 0;
  double last_step_ = 1;  ///< set to the step in the constructor
};

}  // namespace simsr::shell
