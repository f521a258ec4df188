#pragma once
/// \file
/// Facial performances: smooth control curves over frames (core paper §4: four performances of
/// distinct character — amazement, anger, fear, pain — two to train on, two to test), and the
/// controls files a user writes for their own.
///
/// A performance is a matrix of controls, F frames × C named columns. Column names are the kit's
/// expression names (blendshape weights in [0, 1]), optionally `muscle:<name>` (an activation in
/// [0, 1]; absent: from the blendshapes, muscles.hpp) and `jaw` (degrees from the neutral; absent:
/// jawOpen × the hinge's full angle). face_controls() turns one row into FaceControls.
///
/// The built-in four are keyframed: every `key_spacing` frames a key pose = the character's own
/// expressions at a random intensity, plus a little of a random few others ("babble", so every
/// control is seen in training); between keys a C¹ cubic (Catmull–Rom, clamped to [0, 1]); from
/// and to the neutral at the ends. Each character moves the jaw, the lips, the cheeks and the
/// brows, in its own combination. Randomness is a seeded mt19937_64 with its raw bits turned into
/// doubles here, so the curves are the same on every platform for the same seed.
///
///     auto perf = scenario::builtin_performance("anger", kit.expression_names, 120, 7);
///     auto c = scenario::face_controls(perf, 10, face);    // frame 10

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/types.hpp"
#include "face_model.hpp"
#include "face_simulator.hpp"

namespace simsr::scenario {

/// F frames of named controls.
struct Performance {
  std::string name;
  std::vector<std::string> names;  ///< C column names
  Eigen::MatrixXd weights;         ///< F×C

  Index num_frames() const { return weights.rows(); }
};

/// One character: its expressions and their weight at full intensity.
struct Character {
  std::string name;
  std::vector<std::pair<std::string, double>> pose;
};

/// The four characters of the paper's performances. Each moves jaw, lips, cheeks and brows.
inline std::vector<Character> builtin_characters() {
  return {
      {"amazement",
       {{"browInnerUp_L", 0.9}, {"browInnerUp_R", 0.9}, {"browOuterUp_L", 0.8}, {"browOuterUp_R", 0.8}, {"eyeWide_L", 0.7}, {"eyeWide_R", 0.7},
        {"jawOpen", 0.55}, {"mouthFunnel", 0.5}, {"cheekRaiser_L", 0.2}, {"cheekRaiser_R", 0.2}, {"mouthSmile_L", 0.3}, {"mouthSmile_R", 0.3}}},
      {"anger",
       {{"browDown_L", 0.9}, {"browDown_R", 0.9}, {"noseSneer_L", 0.6}, {"noseSneer_R", 0.6}, {"mouthPress_L", 0.5}, {"mouthPress_R", 0.5},
        {"mouthFrown_L", 0.6}, {"mouthFrown_R", 0.6}, {"jawOpen", 0.2}, {"jawForward", 0.3}, {"cheekSquint_L", 0.5}, {"cheekSquint_R", 0.5},
        {"mouthUpperUp_L", 0.4}, {"mouthUpperUp_R", 0.4}}},
      {"fear",
       {{"browInnerUp_L", 0.8}, {"browInnerUp_R", 0.8}, {"browDown_L", 0.3}, {"browDown_R", 0.3}, {"eyeWide_L", 0.8}, {"eyeWide_R", 0.8},
        {"mouthStretch_L", 0.7}, {"mouthStretch_R", 0.7}, {"jawOpen", 0.35}, {"mouthLowerDown_L", 0.5}, {"mouthLowerDown_R", 0.5},
        {"cheekRaiser_L", 0.3}, {"cheekRaiser_R", 0.3}}},
      {"pain",
       {{"browDown_L", 0.8}, {"browDown_R", 0.8}, {"browInnerUp_L", 0.4}, {"browInnerUp_R", 0.4}, {"eyeSquint_L", 0.8}, {"eyeSquint_R", 0.8},
        {"cheekRaiser_L", 0.8}, {"cheekRaiser_R", 0.8}, {"mouthUpperUp_L", 0.6}, {"mouthUpperUp_R", 0.6}, {"mouthStretch_L", 0.5},
        {"mouthStretch_R", 0.5}, {"jawOpen", 0.3}, {"noseSneer_L", 0.4}, {"noseSneer_R", 0.4}}},
  };
}

/// Options of the built-in performances.
struct PerformanceOptions {
  Index frames = 120;        ///< F (the issue: at least 100)
  Index key_spacing = 12;    ///< frames between key poses
  double min_intensity = 0.35, max_intensity = 1.0;  ///< of the character's pose, per key
  Index babble_count = 4;    ///< other expressions mixed into each key
  double babble_max = 0.25;  ///< their largest weight
  Index ramp_frames = 6;     ///< frames from and to the neutral at the ends
};

namespace detail {

/// Uniform double in [0, 1) from the raw 64 bits (the same on every platform).
inline double unit_double(std::mt19937_64& g) { return double(g() >> 11) * 0x1.0p-53; }

inline double catmull_rom(double p0, double p1, double p2, double p3, double t) {
  if (t <= 0) return p1;  // the keys exactly (the polynomial leaves round-off at t = 1)
  if (t >= 1) return p2;
  const double t2 = t * t, t3 = t2 * t;
  return 0.5 * (2 * p1 + (-p0 + p2) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t2 + (-p0 + 3 * p1 - 3 * p2 + p3) * t3);
}

/// FNV-1a of a name, to give every performance its own stream from one seed.
inline std::uint64_t name_hash(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

}  // namespace detail

/// The built-in performance `name` (amazement, anger, fear, pain) over the expressions `names`:
/// columns = the expressions, no muscle or jaw columns (they follow the blendshapes).
/// ArgumentError for an unknown name or a character expression missing from `names`.
inline Performance builtin_performance(const std::string& name, const std::vector<std::string>& names, std::uint64_t seed,
                                       const PerformanceOptions& opt = {}) {
  const auto chars = builtin_characters();
  const auto it = std::find_if(chars.begin(), chars.end(), [&](const Character& c) { return c.name == name; });
  if (it == chars.end()) throw ArgumentError("builtin_performance: no performance '" + name + "' (built in: amazement, anger, fear, pain)");
  if (opt.frames < 2 * opt.ramp_frames + 2 || opt.key_spacing < 2)
    throw ArgumentError("builtin_performance: " + std::to_string(opt.frames) + " frames are too few for key spacing " + std::to_string(opt.key_spacing) +
                        " and ramps of " + std::to_string(opt.ramp_frames));
  const Index C = Index(names.size());
  auto column = [&](const std::string& e) {
    const auto k = std::find(names.begin(), names.end(), e);
    if (k == names.end()) throw ArgumentError("builtin_performance: the expressions have no '" + e + "' (performance '" + name + "')");
    return Index(k - names.begin());
  };
  std::mt19937_64 g(seed ^ detail::name_hash(name));
  // keys: neutral, then poses, then neutral
  const Index inner = opt.frames - 2 * opt.ramp_frames;
  const Index n_keys = std::max<Index>(2, inner / opt.key_spacing + 1);
  std::vector<VecX<>> keys;
  std::vector<double> at;  // frame of each key
  keys.push_back(VecX<>::Zero(C));
  at.push_back(0);
  for (Index k = 0; k < n_keys; ++k) {
    VecX<> w = VecX<>::Zero(C);
    const double intensity = opt.min_intensity + (opt.max_intensity - opt.min_intensity) * detail::unit_double(g);
    for (const auto& [e, full] : it->pose) w[column(e)] = std::min(1.0, full * intensity * (0.8 + 0.4 * detail::unit_double(g)));
    for (Index b = 0; b < opt.babble_count; ++b) {
      const Index c = std::min<Index>(C - 1, Index(detail::unit_double(g) * double(C)));
      w[c] = std::min(1.0, w[c] + opt.babble_max * detail::unit_double(g));
    }
    keys.push_back(w);
    at.push_back(double(opt.ramp_frames) + double(inner - 1) * double(k) / double(n_keys - 1));
  }
  keys.push_back(VecX<>::Zero(C));
  at.push_back(double(opt.frames - 1));
  Performance p;
  p.name = name;
  p.names = names;
  p.weights.resize(opt.frames, C);
  std::size_t seg = 0;
  for (Index f = 0; f < opt.frames; ++f) {
    while (seg + 2 < at.size() && double(f) > at[seg + 1]) ++seg;
    const double t = (double(f) - at[seg]) / (at[seg + 1] - at[seg]);
    const VecX<>& p0 = keys[seg == 0 ? 0 : seg - 1];
    const VecX<>& p1 = keys[seg];
    const VecX<>& p2 = keys[seg + 1];
    const VecX<>& p3 = keys[std::min(seg + 2, keys.size() - 1)];
    for (Index c = 0; c < C; ++c) p.weights(f, c) = std::clamp(detail::catmull_rom(p0[c], p1[c], p2[c], p3[c], t), 0.0, 1.0);
  }
  return p;
}

/// Frame f of `p` as FaceControls for `face` (see the file comment for the columns).
/// ArgumentError for an unknown column, a weight outside [0, 1] (muscles and blendshapes) or a
/// non-finite value, naming the performance, frame and column.
inline FaceControls face_controls(const Performance& p, Index f, const FaceModel& face) {
  if (f < 0 || f >= p.num_frames()) throw ArgumentError("face_controls: frame " + std::to_string(f) + " outside performance '" + p.name + "'");
  if (Index(p.names.size()) != p.weights.cols())
    throw ShapeError("face_controls: performance '" + p.name + "' weights", {p.num_frames(), Index(p.names.size())}, {p.weights.rows(), p.weights.cols()});
  FaceControls c;
  c.blendshapes = VecX<>::Zero(face.num_expressions());
  VecX<> muscles = VecX<>::Constant(Index(face.muscles.size()), -1);
  bool any_muscle = false, have_jaw = false;
  for (std::size_t k = 0; k < p.names.size(); ++k) {
    const std::string& n = p.names[k];
    const double v = p.weights(f, Index(k));
    const auto where = [&] { return "performance '" + p.name + "', frame " + std::to_string(f) + ", control '" + n + "'"; };
    if (!std::isfinite(v)) throw ArgumentError("face_controls: non-finite value at " + where());
    if (n == "jaw") {
      c.jaw = v * std::acos(-1.0) / 180.0;
      have_jaw = true;
      continue;
    }
    if (!(v >= 0 && v <= 1)) throw ArgumentError("face_controls: " + std::to_string(v) + " outside [0, 1] at " + where());
    if (n.rfind("muscle:", 0) == 0) {
      const std::string m = n.substr(7);
      const auto it = std::find_if(face.muscles.begin(), face.muscles.end(), [&](const Muscle& mu) { return mu.spec.name == m; });
      if (it == face.muscles.end()) throw ArgumentError("face_controls: no muscle '" + m + "' at " + where());
      muscles[Index(it - face.muscles.begin())] = v;
      any_muscle = true;
      continue;
    }
    const auto e = std::find(face.expression_names.begin(), face.expression_names.end(), n);
    if (e == face.expression_names.end()) throw ArgumentError("face_controls: no expression '" + n + "' at " + where() + " (columns: expression names, muscle:<name>, jaw)");
    c.blendshapes[Index(e - face.expression_names.begin())] = v;
  }
  if (!have_jaw) {
    const auto e = std::find(face.expression_names.begin(), face.expression_names.end(), "jawOpen");
    if (e != face.expression_names.end()) c.jaw = c.blendshapes[Index(e - face.expression_names.begin())] * face.hinge.angle;
  }
  if (any_muscle) {  // columns given override; the rest follow the blendshapes
    VecX<> from_shapes = muscle_activations(face.muscles, face.expression_names, c.blendshapes);
    for (Index k = 0; k < muscles.size(); ++k)
      if (muscles[k] < 0) muscles[k] = from_shapes[k];
    c.muscles = muscles;
  }
  return c;
}

}  // namespace simsr::scenario
