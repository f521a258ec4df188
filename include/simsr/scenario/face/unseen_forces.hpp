#pragma once
/// \file
/// The "unseen forces" of the core paper §5.3: LR-only frames of the face under forces the paired
/// training data never had, for showing how a network trained on performances generalizes. Two
/// sequences, each from the settled neutral (all controls 0):
///
///     lip_corner_pull   a spring pulls the left mouth corner (the skin point nearest the left
///                       zygomaticus major's insertion) outward and sideways, its target moving
///                       `pull_distance` along normalize(outward normal + lateral) with a
///                       smoothstep ramp over the frames
///     cheek_sphere      a rigid sphere of `sphere_radius` starts `sphere_gap` off the left cheek
///                       (the skin point nearest the middle of the left buccinator) and moves along
///                       the inward normal until its surface is `sphere_depth` past the rest skin,
///                       against the embedded skin points (EmbeddedObstacleContact, κ per unit area)
///
/// Each is written to DIR/unseen/<name>.npz: `lowres` F×N×3 (LR mesh positions), `frame`, and what
/// moved (`spring_point` + `spring_target` F×3, or `sphere_centre` F×3 + `sphere_radius`), with a
/// fingerprint: a finished file of the same model and options is reused. Both are a few seconds
/// at the default size (LR only), so there is no checkpoint; a Newton failure is an Error naming
/// the sequence and frame, and nothing is written for it.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/fingerprint.hpp"
#include "../../io/run_file.hpp"
#include "../../io/npz.hpp"
#include "../../mesh/normals.hpp"
#include "../../physics/forces/embedded_obstacle_contact.hpp"
#include "../../physics/forces/embedded_springs.hpp"
#include "face_datagen.hpp"
#include "face_model.hpp"
#include "face_simulator.hpp"

namespace simsr::scenario {

/// What the unseen-force sequences do (SI units).
struct UnseenForceOptions {
  Index frames = 40;
  double pull_distance = 0.015;     ///< m, how far the spring's target travels
  double pull_stiffness = 5000;     ///< N/m (the skin's track springs hold the corner at ~3,000 N/m)
  double sphere_radius = 0.025;     ///< m
  double sphere_gap = 0.003;        ///< m, between the sphere and the skin at frame 0
  double sphere_depth = 0.012;      ///< m, how far the sphere's surface ends past the rest skin
  double sphere_stiffness = 2e9;    ///< N/m³, penalty per unit skin area
  FaceSimulationOptions simulation;
};

/// Per sequence: its name, frames, seconds and Newton iterations (LR), whether it was reused.
struct UnseenForceStats {
  std::string name;
  Index frames = 0;
  double seconds = 0;
  Index iterations = 0;
  bool reused = false;
  Index max_active_points = 0;  ///< cheek_sphere: the most skin points inside the sphere in a frame
};

namespace detail {

/// The surface vertex nearest to p.
inline Index nearest_surface_vertex(const FaceModel& face, const Vec3<>& p) {
  Index best = 0;
  (face.surface.V.rowwise() - p.transpose()).rowwise().squaredNorm().minCoeff(&best);
  return best;
}

inline const Muscle& muscle_named(const FaceModel& face, const std::string& name) {
  for (const auto& m : face.muscles)
    if (m.spec.name == name) return m;
  throw ArgumentError("unseen forces: the face model has no muscle '" + name + "'");
}

/// The unit normal of the skin at surface vertex v, pointing away from the surface's centroid.
inline Vec3<> outward_normal(const FaceModel& face, Index v) {
  const Points<> n = vertex_normals(face.surface.V, face.surface.F);
  Vec3<> d = n.row(v).transpose();
  const Vec3<> away = face.surface.V.row(v).transpose() - face.surface.V.colwise().mean().transpose();
  return d.dot(away) < 0 ? Vec3<>(-d) : d;
}

inline double smoothstep(double t) { return t * t * (3 - 2 * t); }

}  // namespace detail

/// Simulates both sequences on the LR mesh from its settled neutral and writes
/// DIR/unseen/<name>.npz (file comment).
template <class Linear = physics::ConjugateGradient<physics::Multigrid<>>, exec::HostPolicy P>
std::vector<UnseenForceStats> generate_unseen_force_frames(P policy, const FaceModel& face, const std::filesystem::path& dir, const UnseenForceOptions& opt = {}) {
  if (opt.frames < 2) throw ArgumentError("unseen forces: at least 2 frames, got " + std::to_string(opt.frames));
  for (const double v : {opt.pull_distance, opt.pull_stiffness, opt.sphere_radius, opt.sphere_stiffness})
    if (!(std::isfinite(v) && v > 0)) throw ArgumentError("unseen forces: distances, radius and stiffnesses must be finite and > 0");
  if (!(std::isfinite(opt.sphere_gap) && opt.sphere_gap >= 0 && std::isfinite(opt.sphere_depth) && opt.sphere_depth >= 0))
    throw ArgumentError("unseen forces: the sphere's gap and depth must be finite and ≥ 0");
  const Index N = face.lr.num_vertices(), F = opt.frames;
  const auto out_dir = dir / "unseen";
  std::filesystem::create_directories(out_dir);

  Fingerprint fp;
  const std::string model_print = detail::face_run_fingerprint(face, opt.simulation, nullptr);
  fp.add_bytes(model_print.data(), model_print.size()).add(std::int64_t(F)).add(opt.pull_distance).add(opt.pull_stiffness);
  fp.add(opt.sphere_radius).add(opt.sphere_gap).add(opt.sphere_depth).add(opt.sphere_stiffness);
  const std::string print = fp.hex();

  const FaceControls zero = neutral_controls(face);
  Points<> lr_neutral;
  {
    FaceSimulator<Linear> lr(policy, face, FaceResolution::low, opt.simulation);
    lr.set_controls(zero);
    try {
      lr.step(policy);
    } catch (const ConvergenceError& e) {
      throw Error(std::string("unseen forces: the LR neutral: ") + e.what());
    }
    lr_neutral = lr.positions();
  }
  const Points<> skin0 = deform(policy, face.surface_in_lr, face.lr.T, lr_neutral);  // the neutral skin (LR)
  std::vector<UnseenForceStats> stats;

  const auto run = [&](const std::string& name, auto&& make_term, auto&& move_term, auto&& extra_arrays) {
    UnseenForceStats st;
    st.name = name;
    st.frames = F;
    const auto file = out_dir / (name + ".npz");
    if (std::filesystem::exists(file) && io::fingerprint_of(io::read_npz(file)) == print) {
      st.reused = true;
      stats.push_back(st);
      return;
    }
    FaceSimulator<Linear> lr(policy, face, FaceResolution::low, opt.simulation);
    lr.set_controls(zero);
    lr.set_positions(lr_neutral);
    auto term = make_term();
    data::FrameMatrix<double> lowres(F, 3 * N);
    io::NpzArrays z;
    for (Index f = 0; f < F; ++f) {
      move_term(term, f);
      const auto t0 = std::chrono::steady_clock::now();
      physics::NewtonReport r;
      try {
        r = lr.step_with(policy, term);
      } catch (const ConvergenceError& e) {
        throw Error("unseen forces '" + name + "', frame " + std::to_string(f) + " (LR): " + e.what());
      }
      st.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      st.iterations += r.iterations;
      if (const Index inv = lr.count_inverted(policy)) throw Error("unseen forces '" + name + "', frame " + std::to_string(f) + ": " + std::to_string(inv) + " inverted LR tets");
      Eigen::Map<Points<>>(lowres.row(f).data(), N, 3) = lr.positions();
      extra_arrays(term, f, lr.positions(), st);
    }
    z["lowres"] = io::make_npy<double>({F, N, 3}, lowres.data());
    std::vector<std::int64_t> ids(static_cast<std::size_t>(F));
    for (Index f = 0; f < F; ++f) ids[std::size_t(f)] = f;
    z["frame"] = io::make_npy<std::int64_t>({F}, ids.data());
    io::set_fingerprint(z, print);
    extra_arrays.write(z);
    io::write_npz(file, z);
    stats.push_back(st);
  };

  // lip_corner_pull: one spring on the embedded skin point at the left mouth corner
  {
    const Index corner = detail::nearest_surface_vertex(face, detail::muscle_named(face, "zygomaticus_major_L").insertion);
    Vec3<> lateral = Vec3<>::UnitX();
    if (lateral.dot(face.surface.V.row(corner).transpose() - face.surface.V.colwise().mean().transpose()) < 0) lateral = -lateral;
    const Vec3<> dir_pull = (detail::outward_normal(face, corner) + lateral).normalized();
    const Vec3<> start = skin0.row(corner).transpose();
    struct Record {
      Points<> targets;
      Index corner;
      void write(io::NpzArrays& z) const {
        z["spring_target"] = io::make_npy(targets);
        const std::int64_t c = corner;
        z["spring_point"] = io::make_npy<std::int64_t>({}, &c);
      }
      void operator()(const physics::EmbeddedSprings<>& s, Index f, const Points<>&, UnseenForceStats&) { targets.row(f) = s.targets().row(0); }
    } record{Points<>(F, 3), corner};
    run(
        "lip_corner_pull",
        [&] {
          return physics::EmbeddedSprings<>(face.surface_in_lr, face.lr.T, N, {corner}, VecX<>::Constant(1, opt.pull_stiffness), Points<>(start.transpose()));
        },
        [&](physics::EmbeddedSprings<>& s, Index f) {
          const Vec3<> y = start + opt.pull_distance * detail::smoothstep(double(f) / double(F - 1)) * dir_pull;
          s.set_targets(Points<>(y.transpose()));
        },
        record);
  }

  // cheek_sphere: a sphere pushed into the left cheek against every embedded skin point
  {
    const Muscle& bucc = detail::muscle_named(face, "buccinator_L");
    const Index cheek = detail::nearest_surface_vertex(face, 0.5 * (bucc.insertion + bucc.origin));
    const Vec3<> n = detail::outward_normal(face, cheek);
    const Vec3<> p = skin0.row(cheek).transpose();
    const Vec3<> from = p + (opt.sphere_radius + opt.sphere_gap) * n, to = p + (opt.sphere_radius - opt.sphere_depth) * n;
    struct Record {
      Points<> centres;
      double radius;
      void write(io::NpzArrays& z) const {
        z["sphere_centre"] = io::make_npy(centres);
        z["sphere_radius"] = io::make_npy<double>({}, &radius);
      }
      void operator()(const physics::EmbeddedObstacleContact<physics::Sphere<>>& c, Index f, const Points<>& x, UnseenForceStats& st) {
        centres.row(f) = c.obstacle().centre().transpose();
        st.max_active_points = std::max(st.max_active_points, c.num_active(x));
      }
    } record{Points<>(F, 3), opt.sphere_radius};
    run(
        "cheek_sphere",
        [&] {
          return physics::EmbeddedObstacleContact<physics::Sphere<>>(physics::Sphere<>(from, opt.sphere_radius), face.surface_in_lr, face.lr.T, N,
                                                                     VecX<>(opt.sphere_stiffness * face.surface_area));
        },
        [&](physics::EmbeddedObstacleContact<physics::Sphere<>>& c, Index f) {
          c.obstacle().set_centre(from + detail::smoothstep(double(f) / double(F - 1)) * (to - from));
        },
        record);
  }
  return stats;
}

/// The sequences' figures as JSON (for face_data.json).
inline nlohmann::ordered_json unseen_force_report(const std::vector<UnseenForceStats>& stats) {
  nlohmann::ordered_json a = nlohmann::ordered_json::array();
  for (const auto& s : stats) {
    nlohmann::ordered_json j{{"name", s.name}, {"frames", s.frames}, {"reused", s.reused}};
    if (!s.reused) {
      j["lr_seconds_per_frame"] = s.seconds / double(s.frames);
      j["lr_newton_iterations_per_frame"] = double(s.iterations) / double(s.frames);
      if (s.name == "cheek_sphere") j["most_skin_points_in_contact"] = s.max_active_points;
    }
    a.push_back(j);
  }
  return a;
}

}  // namespace simsr::scenario
