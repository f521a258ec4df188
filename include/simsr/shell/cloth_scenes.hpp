#pragma once
/// \file
/// The SHEET and DISK scenes of Chen et al. 2023 (supplement §3, issue #14), each at a coarse and
/// a fine resolution: the fine rest mesh is the coarse one Loop-subdivided (mesh/loop_subdivision),
/// so the coarse vertices are the fine mesh's first ones and the pins are the same vertex ids.
/// SHEET also takes a fine cloth of its own (`ClothSceneSize::fine_cells`): an N-cell sheet
/// Loop-subdivided, beside a coarse sheet of another cell count, as the supplement's scale study
/// pairs one 8,192-face fine mesh with coarse inputs of 512, 128 and 32 faces (Table 3).
///
///   SHEET  a 1 m square sheet, 8×8 cells (81 vertices; ×3 Loop levels: 4,225, the paper's
///          counts), pinned at its four corners, sagging under gravity; each sequence a pole or a
///          sphere of one of three radii crashing down into it at a sampled spot and speed, pausing,
///          and leaving.
///   DISK   a round tablecloth of radius 0.75 m (6 rings: 127 vertices; ×3 Loop levels: 7,057;
///          the paper's 148 / 7,729 are not a ring count) draped over a round table (a rounded
///          cylinder of radius 0.4 m), held at the table's centre (its first ring: a vase), in a
///          wind whose speed and direction vary per sequence and gust within it.
///
/// Sequences are drawn from a seed (std::mt19937_64), so a dataset is reproducible bitwise.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../mesh/generators.hpp"
#include "../mesh/loop_subdivision.hpp"
#include "../mesh/tri_mesh.hpp"
#include "../neighbors/surface_distance.hpp"
#include "../physics/forces/obstacle_contact.hpp"
#include "../physics/forces/obstacle_shapes.hpp"
#include "wind.hpp"

namespace simsr::shell {

/// The two cloth datasets.
enum class ClothDataset { sheet, disk };

/// "sheet" or "disk".
inline const char* to_string(ClothDataset d) { return d == ClothDataset::sheet ? "sheet" : "disk"; }
/// ArgumentError naming the value for anything but "sheet" and "disk".
inline ClothDataset cloth_dataset(const std::string& name) {
  if (name == "sheet") return ClothDataset::sheet;
  if (name == "disk") return ClothDataset::disk;
  throw ArgumentError("cloth dataset must be 'sheet' or 'disk', got '" + name + "'");
}

/// Both resolutions of a scene's cloth at rest and their pinned vertex ids: pin a of the coarse
/// cloth, pinned[a], and of the fine one, fine_pinned[a], are held at the same spot (the same
/// ids when the fine cloth is the coarse one Loop-subdivided).
struct ClothPair {
  TriMesh<> coarse, fine;
  IndexVector pinned;       ///< coarse vertex ids
  IndexVector fine_pinned;  ///< fine vertex ids, in the order of `pinned`
  /// The fine-from-coarse map (#fine × #coarse) of the subdivided-coarse baseline: Loop's map
  /// when fine = Loop(coarse); for a fine sheet of its own, the coarse sheet Loop-subdivided to
  /// at least the fine one's resolution and read at each fine vertex's closest rest point
  /// (barycentric), so that both are one sparse matrix, rows summing to 1.
  Eigen::SparseMatrix<double> subdivision;
  /// Whether both cloths pin the same vertex ids (always so when fine = Loop(coarse)).
  bool fine_pins_are_coarse_pins() const { return fine_pinned.size() == pinned.size() && (fine_pinned.array() == pinned.array()).all(); }
};

/// The coarse cloth at rest, its pins and the Loop levels to the fine one.
struct ClothSceneSize {
  Index coarse_cells = 8;  ///< SHEET: cells per side (8: 81 vertices); DISK: rings (6: 127 vertices)
  Index levels = 3;        ///< Loop levels to the fine mesh (3: SHEET 4,225 vertices, DISK 7,057)
  /// SHEET: the cells per side of the sheet Loop-subdivided `levels` times into the fine cloth;
  /// 0: coarse_cells (fine = Loop(coarse)). The scale study (supplement Table 3) keeps the fine
  /// cloth, 8 cells × 3 levels, and varies the coarse one: 16 (×16 faces), 8 (×64), 4 (×256).
  Index fine_cells = 0;
  /// The cells the fine cloth is subdivided from.
  Index fine_source_cells() const { return fine_cells > 0 ? fine_cells : coarse_cells; }
};

/// The default size of a dataset (the paper's SHEET counts; DISK's nearest ring count).
inline ClothSceneSize default_scene_size(ClothDataset d) { return d == ClothDataset::sheet ? ClothSceneSize{8, 3} : ClothSceneSize{6, 3}; }

/// The scene's default size with a user's overrides: `cells` when > 0, `levels` when >= 0,
/// `fine_cells` when > 0 (the command line's --cells / --levels / --fine-cells, where 0 / −1 / 0
/// mean "the default").
inline ClothSceneSize scene_size(ClothDataset d, Index cells, Index levels, Index fine_cells = 0) {
  ClothSceneSize s = default_scene_size(d);
  if (cells > 0) s.coarse_cells = cells;
  if (levels >= 0) s.levels = levels;
  if (fine_cells > 0) s.fine_cells = fine_cells;
  return s;
}

namespace detail {

/// The 1 m SHEET of `cells` cells per side, centred on the origin in z = 0, and its four corners.
inline TriMesh<> centred_sheet(Index cells, IndexVector& corners) {
  TriMesh<> m = square_sheet(1.0, cells);
  m.V.rowwise() -= Vec3<>(0.5, 0.5, 0).transpose();
  const Index n = cells + 1;
  corners.resize(4);
  corners << 0, VIndex(n - 1), VIndex(n * (n - 1)), VIndex(n * n - 1);
  return m;
}

/// The Loop levels that bring a sheet of `coarse_cells` cells per side to at least `resolution`.
inline Index loop_levels_to_reach(Index coarse_cells, Index resolution) {
  Index levels = 0;
  while ((coarse_cells << levels) < resolution) ++levels;
  return levels;
}

/// The subdivided-coarse map onto a fine cloth of its own (ClothPair::subdivision): the coarse
/// cloth Loop-subdivided until its cells are no larger than the fine one's (`fine_cells`·2^levels
/// per side), then each fine rest vertex read at its closest point of that surface.
inline Eigen::SparseMatrix<double> resampled_subdivision(const TriMesh<>& coarse, Index coarse_cells, const TriMesh<>& fine, Index fine_resolution) {
  const LoopSubdivision sub = loop_subdivision(coarse.V, coarse.F, loop_levels_to_reach(coarse_cells, fine_resolution));
  TriMesh<> surface;
  surface.V = sub.S * coarse.V;
  surface.F = sub.F;
  const neighbors::SurfaceDistance<> closest(surface);
  std::vector<Eigen::Triplet<double>> w;
  w.reserve(std::size_t(3 * fine.V.rows()));
  for (Index i = 0; i < fine.V.rows(); ++i) {
    const auto hit = closest.closest(fine.V.row(i).transpose());
    for (int c = 0; c < 3; ++c)
      if (hit.barycentric[c] != 0) w.emplace_back(i, surface.F(hit.triangle, c), hit.barycentric[c]);
  }
  Eigen::SparseMatrix<double> sample(fine.V.rows(), surface.V.rows());
  sample.setFromTriplets(w.begin(), w.end());
  return Eigen::SparseMatrix<double>(sample * sub.S);
}

}  // namespace detail

/// The scene's two meshes (see the file comment). ArgumentError for fewer than 2 cells (SHEET),
/// 2 rings (DISK), a negative level count, or a fine cell count for DISK (its pinned vase is the
/// first ring, whose radius is the ring count's: two ring counts would hold different cloths).
inline ClothPair cloth_pair(ClothDataset d, ClothSceneSize size) {
  if (size.levels < 0) throw ArgumentError("cloth_pair: levels must be >= 0, got " + std::to_string(size.levels));
  if (size.fine_cells < 0) throw ArgumentError("cloth_pair: fine_cells must be >= 0 (0: the coarse cells), got " + std::to_string(size.fine_cells));
  ClothPair p;
  const Index fine_cells = size.fine_source_cells();
  if (d == ClothDataset::sheet) {
    if (size.coarse_cells < 2) throw ArgumentError("cloth_pair: a sheet needs >= 2 cells per side, got " + std::to_string(size.coarse_cells));
    if (fine_cells < 2) throw ArgumentError("cloth_pair: the fine sheet needs >= 2 cells per side, got " + std::to_string(fine_cells));
    p.coarse = detail::centred_sheet(size.coarse_cells, p.pinned);
  } else {
    if (size.coarse_cells < 2) throw ArgumentError("cloth_pair: a disk needs >= 2 rings, got " + std::to_string(size.coarse_cells));
    if (fine_cells != size.coarse_cells)
      throw ArgumentError("cloth_pair: DISK's fine cloth is its coarse one subdivided (fine_cells " + std::to_string(size.fine_cells) +
                          " against " + std::to_string(size.coarse_cells) + " rings): the pinned vase is the first ring, whose radius the ring count sets");
    p.coarse = disk_surface(0.75, size.coarse_cells);
    p.coarse.V.col(2).setConstant(0.03);  // just above the table top (z = 0.0)
    p.pinned.resize(7);                   // the centre and the first ring
    for (Index i = 0; i < 7; ++i) p.pinned[i] = VIndex(i);
  }
  if (fine_cells == size.coarse_cells) {
    const LoopSubdivision sub = loop_subdivision(p.coarse.V, p.coarse.F, size.levels);
    p.fine.V = sub.S * p.coarse.V;
    p.fine.F = sub.F;
    p.fine_pinned = p.pinned;
    p.subdivision = sub.S;
    return p;
  }
  IndexVector fine_corners;
  const TriMesh<> fine_source = detail::centred_sheet(fine_cells, fine_corners);
  const LoopSubdivision sub = loop_subdivision(fine_source.V, fine_source.F, size.levels);
  p.fine.V = sub.S * fine_source.V;
  p.fine.F = sub.F;
  p.fine_pinned = fine_corners;  // Loop keeps the source's vertices first, its corners in place
  p.subdivision = detail::resampled_subdivision(p.coarse, size.coarse_cells, p.fine, fine_cells << size.levels);
  return p;
}

/// A SHEET sequence: a pole (a horizontal capsule) or a sphere comes down into the sheet from
/// above, stays, and rises out again.
struct SheetSequence {
  bool pole = false;
  double radius = 0.1;           ///< m
  Vec3<> centre{0, 0, 0};        ///< where it stops (lowest point of its path)
  double heading = 0;            ///< the pole's direction in the xy plane (rad)
  double descent_time = 1.0;     ///< s from the start height to the lowest point
  double hold_time = 0.5;        ///< s at the lowest point
  double start_height = 0.5;     ///< m above the lowest point

  /// The obstacle's centre at time t: down (smoothstep), hold, up again at the same speed.
  Vec3<> centre_at(double t) const {
    auto smooth = [](double s) { s = std::clamp(s, 0.0, 1.0); return s * s * (3 - 2 * s); };
    double up;
    if (t < descent_time) up = 1 - smooth(t / descent_time);
    else if (t < descent_time + hold_time) up = 0;
    else up = smooth((t - descent_time - hold_time) / descent_time);
    return centre + Vec3<>(0, 0, start_height * up);
  }
  /// The obstacle at time t (a sphere is a capsule with equal ends).
  physics::Capsule<> obstacle_at(double t) const {
    const Vec3<> c = centre_at(t);
    if (!pole) return physics::Capsule<>(c, c, radius);
    const Vec3<> half = 0.8 * Vec3<>(std::cos(heading), std::sin(heading), 0);
    return physics::Capsule<>(c - half, c + half, radius);
  }
  /// The seconds it lasts.
  double duration() const { return 2 * descent_time + hold_time; }
};

/// A DISK sequence: wind of a base speed and heading that gusts sinusoidally.
struct DiskSequence {
  double speed = 3;       ///< m/s
  double heading = 0;     ///< rad, in the xy plane
  double gust = 0.5;      ///< relative amplitude of the gusts
  double gust_period = 1.5;  ///< s
  double duration_s = 4;     ///< s
  Air air_at(double t) const {
    const double s = speed * (1 + gust * std::sin(2 * std::numbers::pi * t / gust_period));
    Air a;
    a.velocity = Vec3<>(s * std::cos(heading), s * std::sin(heading), 0);
    return a;
  }
  double duration() const { return duration_s; }
};

/// One parameter of a sequence, named with its unit.
struct SequenceParameter {
  const char* name;
  double value;
};

/// What a sequence was drawn with, in one fixed order: its data's fingerprint holds the values,
/// the dataset summary (cloth_data.json) the names and values.
inline std::vector<SequenceParameter> sequence_parameters(const SheetSequence& q) {
  return {{"pole", double(q.pole)}, {"radius_m", q.radius},       {"centre_x_m", q.centre.x()}, {"centre_y_m", q.centre.y()},
          {"centre_z_m", q.centre.z()}, {"heading_rad", q.heading}, {"descent_s", q.descent_time}, {"hold_s", q.hold_time},
          {"start_height_m", q.start_height}};
}
inline std::vector<SequenceParameter> sequence_parameters(const DiskSequence& q) {
  return {{"wind_m_per_s", q.speed}, {"heading_rad", q.heading}, {"gust", q.gust}, {"gust_period_s", q.gust_period}, {"duration_s", q.duration_s}};
}

/// The table of the DISK scene: a rounded cylinder of radius 0.4 m, its top at z = 0.
inline physics::RoundedCylinder<> disk_table() { return physics::RoundedCylinder<>(Vec3<>(0, 0, -0.4), Vec3<>::UnitZ(), 0.39, 0.39, 0.01); }

/// `count` SHEET sequences drawn from `seed`: the pole and the three sphere radii (0.08, 0.12,
/// 0.16 m) in turn, each at a random spot within 0.25 m of the centre and a random speed.
inline std::vector<SheetSequence> sheet_sequences(Index count, std::uint64_t seed) {
  if (count < 1) throw ArgumentError("sheet_sequences: count must be >= 1, got " + std::to_string(count));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<SheetSequence> out;
  for (Index k = 0; k < count; ++k) {
    SheetSequence s;
    const int kind = int(k % 4);
    s.pole = kind == 0;
    s.radius = kind == 0 ? 0.04 : 0.04 + 0.04 * kind;
    const double r = 0.25 * std::sqrt(u(rng)), phi = 2 * std::numbers::pi * u(rng);
    s.heading = std::numbers::pi * u(rng);
    s.centre = Vec3<>(r * std::cos(phi), r * std::sin(phi), -0.15 - 0.15 * u(rng) - s.radius);
    s.descent_time = 0.8 + 0.8 * u(rng);
    s.hold_time = 0.3 + 0.5 * u(rng);
    s.start_height = 0.6 + s.radius;
    out.push_back(s);
  }
  return out;
}

/// `count` DISK sequences drawn from `seed`: wind speeds 1–8 m/s, any heading, gusts 0–60 %.
inline std::vector<DiskSequence> disk_sequences(Index count, std::uint64_t seed) {
  if (count < 1) throw ArgumentError("disk_sequences: count must be >= 1, got " + std::to_string(count));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<DiskSequence> out;
  for (Index k = 0; k < count; ++k) {
    DiskSequence s;
    s.speed = 1 + 7 * double(k) / double(std::max<Index>(count - 1, 1));  // the speeds spread evenly
    s.heading = 2 * std::numbers::pi * u(rng);
    s.gust = 0.6 * u(rng);
    s.gust_period = 1 + 1.5 * u(rng);
    out.push_back(s);
  }
  return out;
}

}  // namespace simsr::shell
