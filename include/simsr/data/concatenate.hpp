#pragma once
/// \file
/// Several paired-frame sets as one, in order: e.g. the face's one file per performance, so that a
/// split by sequence trains on some performances and tests on others (the paper's protocol).
///
///     std::vector<data::PairedFrames<>> parts{read_paired_frames("amazement.npz"), …};
///     auto all = data::concatenate(parts, {"amazement", …}, data::FrameIds::renumber);
///     auto split = data::by_sequence(all, {"anger", "fear"});

#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "../core/error.hpp"
#include "paired_frames.hpp"

namespace simsr::data {

/// What happens to the parts' frame ids, which must be unique in the result.
enum class FrameIds {
  keep,      ///< as they are; ArgumentError when two parts share one
  renumber,  ///< 0, 1, … over the result (each part's own ids usually restart at 0)
};

/// The controls of the result.
enum class FrameControls {
  keep,  ///< every part must have the same number of control columns (ShapeError otherwise)
  drop,  ///< none (the columns of files written by different performances need not mean the same)
};

/// The frames of `parts` one after another. Sequences are merged by name: a part with sequence
/// labels keeps them, a part without becomes one sequence named `names[i]`. Every part must have
/// the same LR and HR vertex counts (ShapeError naming the part).
template <class S>
PairedFrames<S> concatenate(std::span<const PairedFrames<S>> parts, std::span<const std::string> names, FrameIds ids = FrameIds::keep,
                            FrameControls controls = FrameControls::keep) {
  if (parts.empty()) throw ArgumentError("data::concatenate: no frame sets");
  if (names.size() != parts.size())
    throw ShapeError("data::concatenate: part names (one per part)", {std::int64_t(parts.size())}, {std::int64_t(names.size())});
  const auto label = [&](std::size_t i) { return "data::concatenate: part " + std::to_string(i) + " ('" + names[i] + "')"; };
  Index total = 0;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    parts[i].validate(label(i));
    if (parts[i].num_lr() != parts[0].num_lr() || parts[i].num_hr() != parts[0].num_hr())
      throw ShapeError(label(i) + ": LR and HR vertices (part 0's)", {parts[0].num_lr(), parts[0].num_hr()}, {parts[i].num_lr(), parts[i].num_hr()});
    if (controls == FrameControls::keep && parts[i].num_controls() != parts[0].num_controls())
      throw ShapeError(label(i) + ": control columns (part 0's)", {parts[0].num_controls()}, {parts[i].num_controls()});
    total += parts[i].num_frames();
  }
  PairedFrames<S> out;
  out.lowres.resize(total, parts[0].lowres.cols());
  out.highres.resize(total, parts[0].highres.cols());
  out.controls.resize(total, controls == FrameControls::keep ? parts[0].num_controls() : 0);
  std::unordered_map<std::string, std::int32_t> sequence_of;
  const auto sequence_index = [&](const std::string& name) {
    const auto [it, added] = sequence_of.try_emplace(name, std::int32_t(out.sequence_names.size()));
    if (added) out.sequence_names.push_back(name);
    return it->second;
  };
  std::unordered_map<std::int64_t, std::size_t> id_part;
  Index row = 0;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const auto& p = parts[i];
    const Index f = p.num_frames();
    out.lowres.middleRows(row, f) = p.lowres;
    out.highres.middleRows(row, f) = p.highres;
    if (out.controls.cols() > 0) out.controls.middleRows(row, f) = p.controls;
    for (Index r = 0; r < f; ++r) {
      out.sequence.push_back(sequence_index(p.sequence.empty() ? names[i] : p.sequence_name(r)));
      const std::int64_t id = ids == FrameIds::renumber ? std::int64_t(row + r) : p.ids[std::size_t(r)];
      if (const auto [it, added] = id_part.try_emplace(id, i); !added)
        throw ArgumentError(label(i) + ": frame id " + std::to_string(id) + " is also one of part " + std::to_string(it->second) +
                            "'s (FrameIds::renumber gives new ids)");
      out.ids.push_back(id);
    }
    row += f;
  }
  return out;
}

}  // namespace simsr::data
