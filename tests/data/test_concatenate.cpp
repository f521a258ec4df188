#include <simsr/data/concatenate.hpp>
#include <simsr/data/splits.hpp>

#include <doctest/doctest.h>

#include "../support/error_of.hpp"

#include <random>
#include <set>
#include <string>
#include <vector>

using namespace simsr;
using simsr::test::error_of;

namespace {

/// A part of f random frames; ids 0..f-1 (as every face performance file has them), and with
/// `sequence` non-empty, all frames labelled with it.
data::PairedFrames<> concat_part(std::mt19937& rng, Index f, Index n, Index m, Index c, const std::string& sequence) {
  std::uniform_real_distribution<double> u(-1, 1);
  data::PairedFrames<> p;
  p.lowres = data::FrameMatrix<>::NullaryExpr(f, 3 * n, [&] { return u(rng); });
  p.highres = data::FrameMatrix<>::NullaryExpr(f, 3 * m, [&] { return u(rng); });
  p.controls = data::FrameMatrix<>::NullaryExpr(f, c, [&] { return u(rng); });
  for (Index i = 0; i < f; ++i) p.ids.push_back(i);
  if (!sequence.empty()) {
    p.sequence_names = {"unused", sequence};
    p.sequence.assign(std::size_t(f), 1);
  }
  return p;
}

}  // namespace

TEST_CASE("data::concatenate: rows in order, sequences merged by name, ids renumbered or kept; a split by sequence picks the parts") {
  std::mt19937 rng(11);
  const std::vector<std::string> perf{"amazement", "anger", "fear", "pain"};
  for (int trial = 0; trial < 20; ++trial) {
    const Index n = 2 + trial % 5, m = 3 + trial % 7, c = trial % 3;
    std::vector<data::PairedFrames<>> parts;
    std::vector<std::string> names;
    std::vector<std::string> label_of_part;
    const int k = 2 + trial % 4;
    for (int i = 0; i < k; ++i) {
      // some parts carry their own label, some are named by the caller; two parts may share one
      const std::string seq = perf[std::size_t((i + trial) % 4)];
      const bool labelled = (i + trial) % 2 == 0;
      parts.push_back(concat_part(rng, 1 + (i * 3 + trial) % 6, n, m, c, labelled ? seq : ""));
      names.push_back(labelled ? "file" + std::to_string(i) : seq);
      label_of_part.push_back(seq);
    }
    const auto all = data::concatenate(std::span<const data::PairedFrames<>>(parts), std::span<const std::string>(names), data::FrameIds::renumber);
    Index row = 0;
    for (std::size_t i = 0; i < parts.size(); ++i)
      for (Index r = 0; r < parts[i].num_frames(); ++r, ++row) {
        CHECK(all.lowres.row(row) == parts[i].lowres.row(r));
        CHECK(all.highres.row(row) == parts[i].highres.row(r));
        if (c) CHECK(all.controls.row(row) == parts[i].controls.row(r));
        CHECK(all.sequence_name(row) == label_of_part[i]);
        CHECK(all.ids[std::size_t(row)] == row);
      }
    CHECK(all.num_frames() == row);
    CHECK(all.num_controls() == c);
    std::set<std::string> distinct(label_of_part.begin(), label_of_part.end());
    CHECK(all.sequence_names.size() == distinct.size());  // merged by name, none invented
    all.validate("concatenated");

    // the split by one sequence holds out exactly the rows of the parts labelled with it
    if (distinct.size() > 1) {
      const std::string held = label_of_part[0];
      const auto split = data::by_sequence(all, {held});
      std::vector<Index> expected;
      row = 0;
      for (std::size_t i = 0; i < parts.size(); ++i)
        for (Index r = 0; r < parts[i].num_frames(); ++r, ++row)
          if (label_of_part[i] == held) expected.push_back(row);
      CHECK(split.test == expected);
    }

    // kept ids collide (every part starts at 0): refused, naming both parts
    CHECK(error_of([&] { data::concatenate(std::span<const data::PairedFrames<>>(parts), std::span<const std::string>(names)); }).find("also one of part 0") !=
          std::string::npos);
  }
}

TEST_CASE("data::concatenate: kept ids, dropped controls, and mismatches named") {
  std::mt19937 rng(5);
  std::vector<data::PairedFrames<>> parts{concat_part(rng, 3, 2, 4, 2, ""), concat_part(rng, 2, 2, 4, 5, "")};
  for (auto& id : parts[1].ids) id += 100;
  const std::vector<std::string> names{"a", "b"};
  const std::span<const data::PairedFrames<>> ps(parts);
  const std::span<const std::string> ns(names);
  CHECK(error_of([&] { data::concatenate(ps, ns); }).find("control columns") != std::string::npos);
  const auto dropped = data::concatenate(ps, ns, data::FrameIds::keep, data::FrameControls::drop);
  CHECK(dropped.num_controls() == 0);
  CHECK(dropped.ids == std::vector<std::int64_t>{0, 1, 2, 100, 101});
  CHECK(dropped.sequence_names == std::vector<std::string>{"a", "b"});

  parts[1] = concat_part(rng, 2, 3, 4, 2, "");  // another LR size
  CHECK_THROWS_AS(data::concatenate(std::span<const data::PairedFrames<>>(parts), ns, data::FrameIds::renumber), ShapeError);
  CHECK_THROWS_AS(data::concatenate(std::span<const data::PairedFrames<>>(parts), std::span<const std::string>(names.data(), 1)), ShapeError);
  CHECK_THROWS_AS(data::concatenate(std::span<const data::PairedFrames<>>(), std::span<const std::string>()), ArgumentError);
}
