#pragma once
/// \file
/// One side of a frame set: F frames of V×3 positions under one key of an .npz (`lowres` for a
/// performance's LR frames, `highres` for predicted or true HR frames), with their `frame` ids —
/// what `simsr infer` reads and writes and `simsr eval` compares.
///
///     data::FrameSet lr = data::read_frame_set("performance.npz", "lowres", lr.num_vertices());
///     data::write_frame_set("prediction.npz", "highres", predicted);
///     std::vector<Index> rows = data::match_frame_ids(predicted.ids, truth.ids, "truth.npz");

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../io/npz.hpp"
#include "paired_frames.hpp"

namespace simsr::data {

/// F frames of V×3 positions and their ids.
struct FrameSet {
  FrameMatrix<Scalar> positions;   ///< F×3V
  std::vector<std::int64_t> ids;   ///< F (0..F-1 when the file has no `frame` array)
  bool has_ids = false;            ///< whether the file held a `frame` array

  Index num_frames() const { return positions.rows(); }
  Index num_vertices() const { return positions.cols() / 3; }
  /// The frames at `rows` (positions in this set), ids following.
  FrameSet select(const std::vector<Index>& rows) const {
    FrameSet out;
    out.has_ids = has_ids;
    out.positions.resize(Index(rows.size()), positions.cols());
    for (std::size_t i = 0; i < rows.size(); ++i) {
      frame(rows[i]);  // range check
      out.positions.row(Index(i)) = positions.row(rows[i]);
      out.ids.push_back(ids[std::size_t(rows[i])]);
    }
    return out;
  }
  Eigen::Map<const Points<Scalar>> frame(Index f) const {
    if (f < 0 || f >= num_frames()) throw ArgumentError("frame set: frame " + std::to_string(f) + " out of range [0, " + std::to_string(num_frames()) + ")");
    return {positions.row(f).data(), num_vertices(), 3};
  }
};

/// `key` (F×V×3, float32 or float64, every value finite) and the optional `frame` ids (integers,
/// one per frame, distinct) of an .npz; V must be `vertices`.
inline FrameSet read_frame_set(const std::filesystem::path& file, const std::string& key, Index vertices) {
  const std::string source = file.string();
  io::NpzReader z(file);
  if (z.contains(key)) {
    const io::NpyArray a = z.read(key);
    if (a.dtype.kind != io::NpyKind::Float || (a.dtype.itemsize != 4 && a.dtype.itemsize != 8))
      throw ArgumentError(source + ": " + key + " has dtype " + a.dtype.name() + ", expected float32 or float64");
  }
  FrameSet s;
  s.positions = detail::read_frame_array<Scalar>(z, source, key.c_str());
  if (s.num_vertices() != vertices)
    throw ShapeError(source + ": " + key + " vertices", {s.num_frames(), vertices, 3}, {s.num_frames(), s.num_vertices(), 3});
  const Index f = s.num_frames();
  s.has_ids = z.contains("frame");
  if (s.has_ids) {
    const io::NpyArray a = z.read("frame");
    if (a.dtype.kind != io::NpyKind::Int && a.dtype.kind != io::NpyKind::UInt)
      throw ArgumentError(source + ": frame has dtype " + a.dtype.name() + ", expected integer frame ids");
    if (a.ndim() != 1 || a.shape[0] != f) throw ShapeError(source + ": frame (one id per frame)", {f}, a.shape);
    s.ids = a.to_vector<std::int64_t>();
    std::map<std::int64_t, Index> seen;
    for (Index i = 0; i < f; ++i)
      if (!seen.emplace(s.ids[std::size_t(i)], i).second)
        throw ArgumentError(source + ": frame id " + std::to_string(s.ids[std::size_t(i)]) + " appears twice");
  } else {
    for (Index i = 0; i < f; ++i) s.ids.push_back(i);
  }
  for (Index r = 0; r < f; ++r)
    for (Index c = 0; c < s.positions.cols(); ++c)
      if (!std::isfinite(s.positions(r, c)))
        throw ArgumentError(source + ": " + key + " frame " + std::to_string(r) +
                            (s.has_ids ? " (id " + std::to_string(s.ids[std::size_t(r)]) + ")" : std::string()) + ", vertex " +
                            std::to_string(c / 3) + " is not finite");
  return s;
}

/// Writes `key` (F×V×3 float64) and `frame` (the ids) atomically as a compressed .npz.
inline void write_frame_set(const std::filesystem::path& file, const std::string& key, const FrameSet& s) {
  if (Index(s.ids.size()) != s.num_frames()) throw ShapeError("write_frame_set: frame ids", {s.num_frames()}, {Index(s.ids.size())});
  if (!s.positions.allFinite()) throw ArgumentError("write_frame_set: " + file.string() + ": refusing to write non-finite positions");
  io::NpzArrays z;
  z[key] = io::make_npy<double>({s.num_frames(), s.num_vertices(), 3}, s.positions.data());
  z["frame"] = io::make_npy<std::int64_t>({s.num_frames()}, s.ids.data());
  io::write_npz(file, z, io::NpzCompression::Deflate);
}

/// For each id of `ids`, the row of `reference_ids` holding it. ShapeError naming `reference`
/// (the file of reference_ids) for an id it lacks.
inline std::vector<Index> match_frame_ids(const std::vector<std::int64_t>& ids, const std::vector<std::int64_t>& reference_ids,
                                          const std::string& reference) {
  std::map<std::int64_t, Index> where;
  for (Index f = 0; f < Index(reference_ids.size()); ++f) where.emplace(reference_ids[std::size_t(f)], f);
  std::vector<Index> rows;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const auto it = where.find(ids[i]);
    if (it == where.end())
      throw ShapeError(reference + ": no frame with id " + std::to_string(ids[i]) + " (frame " + std::to_string(i) + " of the other file)",
                       {Index(ids.size())}, {Index(reference_ids.size())});
    rows.push_back(it->second);
  }
  return rows;
}

}  // namespace simsr::data
