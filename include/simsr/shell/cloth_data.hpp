#pragma once
/// \file
/// A cloth dataset that generate_cloth_data (cloth_datagen.hpp) wrote, read back for training and
/// evaluation: the coarse/fine pair rebuilt from DIR/cloth_data.json (scene, coarse size, Loop
/// levels, the fine cloth's cells), every sequence's frames, its split, and the scene's obstacle at
/// the end of any frame (the sequences are rebuilt from the seed, so nothing of the scene is
/// stored twice).
///
///     const shell::ClothData data = shell::read_cloth_data("sheet_data");
///     data.with_obstacle(k, f, [&](const auto& obstacle) { refine.refine(exec::seq, obstacle, x); });

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../core/error.hpp"
#include "../data/paired_frames.hpp"
#include "../io/text_file.hpp"
#include "cloth_scenes.hpp"

namespace simsr::shell {

/// One sequence of a dataset: frames f = 0..F−1 end at time (f+1)·frame_time.
struct ClothSequenceFrames {
  std::string name;
  Index index = 0;    ///< k of the generator (its obstacle or wind)
  bool test = false;  ///< held out (the supplement holds out whole sequences)
  std::vector<Points<>> coarse, fine;
  Index num_frames() const { return static_cast<Index>(coarse.size()); }
};

struct ClothData {
  ClothDataset scene = ClothDataset::sheet;
  ClothSceneSize size;
  std::uint64_t seed = 0;
  double frame_time = 0;
  ClothPair pair;
  std::vector<ClothSequenceFrames> sequences;
  std::vector<SheetSequence> sheet;  ///< SHEET: every sequence's obstacle motion
  std::vector<DiskSequence> disk;    ///< DISK: every sequence's wind

  Index num_coarse() const { return pair.coarse.V.rows(); }
  Index num_fine() const { return pair.fine.V.rows(); }

  /// fn(obstacle) with the obstacle of sequence `index` at the end of its frame f.
  template <class Fn>
  void with_obstacle(Index index, Index f, Fn&& fn) const {
    if (scene == ClothDataset::sheet) {
      if (index < 0 || index >= static_cast<Index>(sheet.size()))
        throw ArgumentError("ClothData::with_obstacle: no sequence " + std::to_string(index));
      fn(sheet[std::size_t(index)].obstacle_at(double(f + 1) * frame_time));
    } else {
      fn(disk_table());
    }
  }
};

/// Reads DIR (cloth_data.json and its sequences). `only_split` = "train" or "test" reads those
/// sequences only ("" all). ParseError for a missing or malformed summary or sequence file,
/// ShapeError when a sequence's vertex counts are not the summary's.
inline ClothData read_cloth_data(const std::filesystem::path& dir, const std::string& only_split = "") {
  const auto summary = dir / "cloth_data.json";
  const nlohmann::json j = nlohmann::json::parse(io::read_text_file(summary, "is this a folder `simsr datagen --scenario sheet|disk` wrote?"), nullptr, false);
  if (j.is_discarded()) throw ParseError(summary.string(), 0, "not valid JSON");
  ClothData d;
  try {
    d.scene = cloth_dataset(j.at("scene").get<std::string>());
    d.size.coarse_cells = j.at("coarse_cells").get<Index>();
    d.size.levels = j.at("fine").at("loop_levels").get<Index>();
    // a fine cloth of its own (ClothSceneSize::fine_cells); data written before the field: Loop(coarse)
    d.size.fine_cells = j.at("fine").value("cells", Index(0));
    d.seed = j.at("seed").get<std::uint64_t>();
    d.frame_time = j.at("frame_time_s").get<double>();
  } catch (const nlohmann::json::exception& e) {
    throw ParseError(summary.string(), 0, std::string("missing or wrong field: ") + e.what());
  }
  d.pair = cloth_pair(d.scene, d.size);
  const Index N = d.num_coarse(), M = d.num_fine();
  if (j.at("coarse").at("vertices").get<Index>() != N || j.at("fine").at("vertices").get<Index>() != M)
    throw ShapeError(summary.string() + ": vertex counts (coarse, fine) rebuilt from its scene",
                     {N, M}, {j["coarse"]["vertices"].get<Index>(), j["fine"]["vertices"].get<Index>()});
  const auto& seqs = j.at("sequences");
  const Index count = static_cast<Index>(seqs.size());
  if (d.scene == ClothDataset::sheet) d.sheet = sheet_sequences(count, d.seed);
  else d.disk = disk_sequences(count, d.seed);
  for (Index k = 0; k < count; ++k) {
    const auto& e = seqs[std::size_t(k)];
    ClothSequenceFrames s;
    s.name = e.at("name").get<std::string>();
    s.index = k;
    s.test = e.at("split").get<std::string>() == "test";
    if (!only_split.empty() && (only_split == "test") != s.test) continue;
    const auto file = dir / (s.name + ".npz");
    const data::PairedFrames<> p = data::read_paired_frames(file, N, M);
    if (p.num_frames() != e.at("frames").get<Index>())
      throw ShapeError(file.string() + ": frames (cloth_data.json says)", {e["frames"].get<Index>()}, {p.num_frames()});
    for (Index f = 0; f < p.num_frames(); ++f) {
      s.coarse.emplace_back(p.lr(f));
      s.fine.emplace_back(p.hr(f));
    }
    d.sequences.push_back(std::move(s));
  }
  return d;
}

}  // namespace simsr::shell
