#pragma once
/// \file
/// The checkpoints of a resumable data run (the face's and the cloths' datagen; the file helpers
/// they share, fingerprints and named arrays, are io/run_file.hpp): a sequence's checkpoint
/// holds its frames so far
/// (PairedFrames' lowres / highres rows) and whatever state the simulators need to go on.
///
///     io::NpzArrays z = data::frames_checkpoint(frames, done, print);  // fingerprint included   // + the solvers' state
///     z["x"] = io::make_npy(sim.positions());
///     io::write_npz(partial, z);
///     ...
///     const Index start = data::resume_frames(io::read_npz(partial), partial.string(), frames);

#include <cstdint>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../io/npz.hpp"
#include "../io/run_file.hpp"
#include "paired_frames.hpp"

namespace simsr::data {

/// A checkpoint of `frames` after its first `done` rows: frames_done, lowres, highres and the
/// fingerprint (the caller adds its solvers' state).
inline io::NpzArrays frames_checkpoint(const PairedFrames<>& frames, Index done, const std::string& print) {
  io::NpzArrays z;
  const std::int64_t d = done;
  z["frames_done"] = io::make_npy<std::int64_t>({}, &d);
  const FrameMatrix<double> lo = frames.lowres.topRows(done), hi = frames.highres.topRows(done);
  z["lowres"] = io::make_npy(lo);
  z["highres"] = io::make_npy(hi);
  io::set_fingerprint(z, print);
  return z;
}

/// Copies a checkpoint's frames into the first rows of `frames` (sized for the whole sequence)
/// and returns how many there are. ArgumentError naming the file for a count outside
/// [1, frames] or frame arrays of another shape.
inline Index resume_frames(const io::NpzArrays& z, const std::string& file, PairedFrames<>& frames) {
  const Index F = frames.num_frames();
  if (!z.contains("frames_done")) throw ArgumentError(file + ": no 'frames_done' array");
  const Index start = Index(z.at("frames_done").item<std::int64_t>());
  if (start < 1 || start > F) throw ArgumentError(file + ": frames_done " + std::to_string(start) + " outside [1, " + std::to_string(F) + "]");
  const auto lo = z.at("lowres").to_matrix<double>(), hi = z.at("highres").to_matrix<double>();
  if (lo.rows() != start || lo.cols() != frames.lowres.cols() || hi.rows() != start || hi.cols() != frames.highres.cols())
    throw ArgumentError(file + ": its frame arrays do not match frames_done and the meshes");
  frames.lowres.topRows(start) = lo;
  frames.highres.topRows(start) = hi;
  return start;
}

}  // namespace simsr::data
