#pragma once
/// \file
/// Train/test splits of a paired frame set, as positions (rows) in the set:
///
///     data::Split s = data::holdout_every(frames.num_frames(), 4);   // rows 0, 4, 8, … held out (the bunny)
///     data::Split s = data::by_sequence(frames, {"anger", "fear"});   // whole performances held out (the face)
///     auto train = frames.select(s.train), test = frames.select(s.test);
///
/// Interleaved hold-outs measure interpolation between neighbouring frames of the same motion;
/// holding out whole sequences measures generalization to performances never seen (SPEC §7, the
/// paper's amazement + pain → anger + fear).

#include <algorithm>
#include <span>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "paired_frames.hpp"

namespace simsr::data {

/// Rows of a frame set used for training and for testing (disjoint, ascending).
struct Split {
  std::vector<Index> train;
  std::vector<Index> test;
};

/// Rows r with r % every == 0 are held out; `every` = 0 holds nothing out. ArgumentError for
/// every = 1 (nothing left to train on) or < 0.
inline Split holdout_every(Index frames, Index every) {
  if (every < 0 || every == 1)
    throw ArgumentError("hold-out: every n-th frame needs n = 0 (none) or n ≥ 2, got " + std::to_string(every));
  Split s;
  for (Index f = 0; f < frames; ++f) (every > 0 && f % every == 0 ? s.test : s.train).push_back(f);
  return s;
}

/// Frames of the named sequences are held out, all others train. ArgumentError when the set has
/// no sequences, a name is not one of them, or no frame is left on either side.
template <class S>
Split by_sequence(const PairedFrames<S>& frames, std::span<const std::string> test_sequences) {
  if (frames.sequence.empty()) throw ArgumentError("split by sequence: the frame set has no 'sequence' labels");
  std::vector<char> is_test(frames.sequence_names.size(), 0);
  for (const auto& name : test_sequences) {
    const auto it = std::find(frames.sequence_names.begin(), frames.sequence_names.end(), name);
    if (it == frames.sequence_names.end()) {
      std::string known;
      for (const auto& n : frames.sequence_names) known += (known.empty() ? "" : ", ") + n;
      throw ArgumentError("split by sequence: no sequence '" + name + "' (the set has: " + known + ")");
    }
    is_test[std::size_t(it - frames.sequence_names.begin())] = 1;
  }
  Split s;
  for (Index f = 0; f < frames.num_frames(); ++f) (is_test[std::size_t(frames.sequence[std::size_t(f)])] ? s.test : s.train).push_back(f);
  if (s.train.empty() || s.test.empty())
    throw ArgumentError("split by sequence: " + std::string(s.train.empty() ? "no training frame is left" : "no frame is held out"));
  return s;
}

template <class S>
Split by_sequence(const PairedFrames<S>& frames, std::initializer_list<std::string> test_sequences) {
  const std::vector<std::string> v(test_sequences);
  return by_sequence(frames, std::span<const std::string>(v));
}

}  // namespace simsr::data
