#pragma once
/// \file
/// Paired frame sets: the LR volume and the HR surface of the same instants (SPEC §4, §7), as the
/// authors' `train_frames.npz` stores them and as simsr writes them:
///
///     lowres    F×N×3  LR vertex positions (absolute, mesh units)
///     highres   F×M×3  HR vertex positions of the same frames
///     frame     F      frame ids (int64; optional, 0..F-1 when absent)
///     controls  F×C    the control vector that produced each frame (optional; e.g. activations,
///                      jaw angle — the `--controls` interface of a scenario)
///     sequence  F      sequence index per frame (int32; optional), naming
///     sequence_names  the sequences (unicode; e.g. "amazement", "pain"), for splits by sequence
///
///     data::PairedFrames<> frames = data::read_paired_frames("train_frames.npz", lr.num_vertices(), hr.num_vertices());
///     auto d = data::displacements(frames, lr.V, hr.V);     // the same frames relative to the rest shapes
///     d.lr(f);  d.hr(f);                                    // N×3 and M×3 views of frame f
///
/// Every reader check names the file and the array: a missing or misshapen array, a frame count
/// that differs between arrays, a non-finite value (with frame and vertex), duplicate frame ids, a
/// sequence index without a name.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../io/npz.hpp"

namespace simsr::data {

/// F rows, one frame each: a frame's V×3 positions flattened row-major (vertex, xyz).
template <class S = Scalar>
using FrameMatrix = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Upper bound on the frames of one file: far above any data set here (the paper's face has ~2,000
/// frames); a header declaring more is a hostile or corrupt file, refused before allocating.
inline constexpr Index max_frames = 1'000'000;

/// F paired LR/HR frames (see the file comment). Positions or displacements, as the producer says.
template <class S = Scalar>
struct PairedFrames {
  using scalar_type = S;
  FrameMatrix<S> lowres;                    ///< F×3N
  FrameMatrix<S> highres;                   ///< F×3M
  std::vector<std::int64_t> ids;            ///< F frame ids
  FrameMatrix<S> controls;                  ///< F×C control vectors (C = 0: none)
  std::vector<std::int32_t> sequence;       ///< F sequence indices into sequence_names (empty: none)
  std::vector<std::string> sequence_names;  ///< names of the sequences

  /// F frames of one sequence named `name`, N LR and M HR vertices, ids 0..F−1, positions to be
  /// filled (uninitialized): what a simulation of one sequence writes into.
  static PairedFrames one_sequence(Index F, Index N, Index M, std::string name) {
    PairedFrames out;
    out.lowres.resize(F, 3 * N);
    out.highres.resize(F, 3 * M);
    out.ids.resize(std::size_t(F));
    for (Index f = 0; f < F; ++f) out.ids[std::size_t(f)] = f;
    out.sequence.assign(std::size_t(F), 0);
    out.sequence_names = {std::move(name)};
    return out;
  }

  Index num_frames() const { return lowres.rows(); }
  Index num_lr() const { return lowres.cols() / 3; }
  Index num_hr() const { return highres.cols() / 3; }
  Index num_controls() const { return controls.cols(); }

  /// Frame f's N×3 LR and M×3 HR rows, as views (no copy).
  Eigen::Map<const Points<S>> lr(Index f) const { return {lowres.row(checked(f)).data(), num_lr(), 3}; }
  Eigen::Map<const Points<S>> hr(Index f) const { return {highres.row(checked(f)).data(), num_hr(), 3}; }
  Eigen::Map<Points<S>> lr(Index f) { return {lowres.row(checked(f)).data(), num_lr(), 3}; }
  Eigen::Map<Points<S>> hr(Index f) { return {highres.row(checked(f)).data(), num_hr(), 3}; }

  /// The name of frame f's sequence ("" when the set has none).
  const std::string& sequence_name(Index f) const {
    static const std::string none;
    return sequence.empty() ? none : sequence_names[std::size_t(sequence[std::size_t(checked(f))])];
  }

  /// The frames at `rows` (positions in this set, in that order): ids, controls and sequences follow.
  PairedFrames select(std::span<const Index> rows) const {
    PairedFrames out;
    const Index n = Index(rows.size());
    out.lowres.resize(n, lowres.cols());
    out.highres.resize(n, highres.cols());
    out.controls.resize(n, controls.cols());
    out.sequence_names = sequence_names;
    for (Index i = 0; i < n; ++i) {
      const Index f = checked(rows[std::size_t(i)]);
      out.lowres.row(i) = lowres.row(f);
      out.highres.row(i) = highres.row(f);
      if (controls.cols()) out.controls.row(i) = controls.row(f);
      out.ids.push_back(ids[std::size_t(f)]);
      if (!sequence.empty()) out.sequence.push_back(sequence[std::size_t(f)]);
    }
    return out;
  }

  /// Throws (naming `source`) unless the arrays agree: 3 columns per vertex, F rows everywhere,
  /// finite values, unique ids, sequence indices within sequence_names.
  void validate(const std::string& source) const {
    const Index f = num_frames();
    if (lowres.cols() % 3 != 0 || highres.cols() % 3 != 0)
      throw ShapeError(source + ": lowres/highres (F×V×3)", {f, -1, 3}, {lowres.cols(), highres.cols()});
    if (highres.rows() != f) throw ShapeError(source + ": highres frames (as many as lowres)", {f}, {highres.rows()});
    if (Index(ids.size()) != f) throw ShapeError(source + ": frame ids", {f}, {Index(ids.size())});
    if (controls.cols() > 0 && controls.rows() != f) throw ShapeError(source + ": controls (F×C)", {f, controls.cols()}, {controls.rows(), controls.cols()});
    check_finite(source, "lowres", lowres);
    check_finite(source, "highres", highres);
    check_finite(source, "controls", controls);
    std::unordered_set<std::int64_t> seen;
    for (Index i = 0; i < f; ++i)
      if (!seen.insert(ids[std::size_t(i)]).second)
        throw ArgumentError(source + ": frame id " + std::to_string(ids[std::size_t(i)]) + " appears twice (row " + std::to_string(i) + ")");
    if (!sequence.empty()) {
      if (Index(sequence.size()) != f) throw ShapeError(source + ": sequence", {f}, {Index(sequence.size())});
      for (Index i = 0; i < f; ++i) {
        const auto s = sequence[std::size_t(i)];
        if (s < 0 || std::size_t(s) >= sequence_names.size())
          throw ArgumentError(source + ": frame " + std::to_string(i) + " has sequence " + std::to_string(s) + ", but " +
                              std::to_string(sequence_names.size()) + " sequence names are given");
      }
    }
  }

 private:
  Index checked(Index f) const {
    if (f < 0 || f >= num_frames())
      throw ArgumentError("paired frames: frame " + std::to_string(f) + " out of range [0, " + std::to_string(num_frames()) + ")");
    return f;
  }
  static void check_finite(const std::string& source, const char* name, const FrameMatrix<S>& m) {
    for (Index r = 0; r < m.rows(); ++r)
      for (Index c = 0; c < m.cols(); ++c)
        if (!std::isfinite(double(m(r, c))))
          throw ArgumentError(source + ": " + name + " frame " + std::to_string(r) + ", " +
                              (std::string(name) == "controls" ? "control " + std::to_string(c) : "vertex " + std::to_string(c / 3)) +
                              " is not finite (" + std::to_string(double(m(r, c))) + ")");
  }
};

namespace detail {
/// An F×V×3 array of the archive as F×3V rows (any numeric dtype, any order).
template <class S>
FrameMatrix<S> read_frame_array(io::NpzReader& z, const std::string& source, const char* name) {
  if (!z.contains(name)) throw ArgumentError(source + ": no array '" + std::string(name) + "' (paired frames need lowres and highres)");
  const io::NpyArray a = z.read(name);
  if (a.ndim() != 3 || a.shape[2] != 3) throw ShapeError(source + ": " + name + " (F×V×3)", {-1, -1, 3}, a.shape);
  if (a.shape[0] > max_frames) throw ShapeError(source + ": " + name + " frames (at most " + std::to_string(max_frames) + ")", {max_frames}, {a.shape[0]});
  FrameMatrix<S> m(a.shape[0], a.shape[1] * 3);
  const auto v = a.to_vector<S>();
  std::copy(v.begin(), v.end(), m.data());
  return m;
}
}  // namespace detail

/// Reads a paired-frame .npz (file comment). Throws ParseError for a damaged archive, ShapeError
/// / ArgumentError naming the array for anything the layout forbids.
inline PairedFrames<Scalar> read_paired_frames(const std::filesystem::path& file) {
  const std::string source = file.string();
  io::NpzReader z(file);
  PairedFrames<Scalar> p;
  p.lowres = detail::read_frame_array<Scalar>(z, source, "lowres");
  p.highres = detail::read_frame_array<Scalar>(z, source, "highres");
  const Index f = p.lowres.rows();
  if (p.highres.rows() != f) throw ShapeError(source + ": highres frames (as many as lowres)", {f}, {p.highres.rows()});
  if (z.contains("frame")) {
    const io::NpyArray a = z.read("frame");
    if (a.ndim() != 1 || a.shape[0] != f) throw ShapeError(source + ": frame (one id per frame)", {f}, a.shape);
    p.ids = a.to_vector<std::int64_t>();
  } else {
    p.ids.resize(std::size_t(f));
    for (Index i = 0; i < f; ++i) p.ids[std::size_t(i)] = i;
  }
  if (z.contains("controls")) {
    const io::NpyArray a = z.read("controls");
    if (a.ndim() != 2 || a.shape[0] != f) throw ShapeError(source + ": controls (F×C)", {f, -1}, a.shape);
    p.controls = a.to_matrix<Scalar>();
  } else {
    p.controls.resize(f, 0);
  }
  if (z.contains("sequence") != z.contains("sequence_names"))
    throw ArgumentError(source + ": 'sequence' and 'sequence_names' come together (one is missing)");
  if (z.contains("sequence")) {
    const io::NpyArray a = z.read("sequence");
    if (a.ndim() != 1 || a.shape[0] != f) throw ShapeError(source + ": sequence (one index per frame)", {f}, a.shape);
    p.sequence = a.to_vector<std::int32_t>();
    p.sequence_names = z.read("sequence_names").to_strings();
  }
  p.validate(source);
  return p;
}

/// read_paired_frames, and the vertex counts must be the rest shapes' (N LR, M HR vertices).
inline PairedFrames<Scalar> read_paired_frames(const std::filesystem::path& file, Index num_lr, Index num_hr) {
  PairedFrames<Scalar> p = read_paired_frames(file);
  if (p.num_lr() != num_lr)
    throw ShapeError(file.string() + ": lowres vertices (the LR rest mesh's)", {p.num_frames(), num_lr, 3}, {p.num_frames(), p.num_lr(), 3});
  if (p.num_hr() != num_hr)
    throw ShapeError(file.string() + ": highres vertices (the HR rest surface's)", {p.num_frames(), num_hr, 3}, {p.num_frames(), p.num_hr(), 3});
  return p;
}

/// The arrays of a paired-frame .npz (the layout read_paired_frames reads), float64.
template <class S>
io::NpzArrays paired_frame_arrays(const PairedFrames<S>& p) {
  p.validate("paired frames to write");
  io::NpzArrays out;
  const Index f = p.num_frames();
  auto frames = [&](const FrameMatrix<S>& m, Index v) {
    const FrameMatrix<double> d = m.template cast<double>();
    return io::make_npy<double>({f, v, 3}, d.data());
  };
  out["lowres"] = frames(p.lowres, p.num_lr());
  out["highres"] = frames(p.highres, p.num_hr());
  out["frame"] = io::make_npy<std::int64_t>({f}, p.ids.data());
  if (p.num_controls() > 0) {
    const FrameMatrix<double> c = p.controls.template cast<double>();
    out["controls"] = io::make_npy<double>({f, p.num_controls()}, c.data());
  }
  if (!p.sequence.empty()) {
    out["sequence"] = io::make_npy<std::int32_t>({f}, p.sequence.data());
    out["sequence_names"] = io::make_npy(p.sequence_names);
  }
  return out;
}

/// Writes `p` as a paired-frame .npz (atomically, like every simsr writer).
template <class S>
void write_paired_frames(const std::filesystem::path& file, const PairedFrames<S>& p) {
  io::write_npz(file, paired_frame_arrays(p));
}

/// The same frames relative to the rest shapes (lowres − lr_rest, highres − hr_rest per frame):
/// what interpolators and networks consume. ShapeError when a rest shape's size differs.
template <class S, class DL, class DH>
PairedFrames<S> displacements(const PairedFrames<S>& positions, const Eigen::MatrixBase<DL>& lr_rest, const Eigen::MatrixBase<DH>& hr_rest) {
  if (lr_rest.rows() != positions.num_lr() || lr_rest.cols() != 3)
    throw ShapeError("data::displacements: LR rest shape", {positions.num_lr(), 3}, {lr_rest.rows(), lr_rest.cols()});
  if (hr_rest.rows() != positions.num_hr() || hr_rest.cols() != 3)
    throw ShapeError("data::displacements: HR rest shape", {positions.num_hr(), 3}, {hr_rest.rows(), hr_rest.cols()});
  PairedFrames<S> d = positions;
  for (Index f = 0; f < d.num_frames(); ++f) {
    d.lr(f) -= lr_rest.template cast<S>();
    d.hr(f) -= hr_rest.template cast<S>();
  }
  return d;
}

}  // namespace simsr::data
