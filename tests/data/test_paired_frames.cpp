#include <simsr/data/frame_set.hpp>
#include <simsr/data/paired_frames.hpp>
#include <simsr/data/splits.hpp>

#include <doctest/doctest.h>

#include "../support/error_of.hpp"

#include <filesystem>
#include <random>
#include <set>
#include <string>

using namespace simsr;
using simsr::test::error_of;

namespace {

std::filesystem::path tmp(const std::string& name) {
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "data";
  std::filesystem::create_directories(dir);
  return dir / name;
}

data::PairedFrames<> random_frames(std::mt19937& rng, Index f, Index n, Index m, Index c, bool sequences) {
  std::normal_distribution<double> g(0.0, 10.0);
  data::PairedFrames<> p;
  p.lowres = data::FrameMatrix<>::NullaryExpr(f, 3 * n, [&] { return g(rng); });
  p.highres = data::FrameMatrix<>::NullaryExpr(f, 3 * m, [&] { return g(rng); });
  p.controls = data::FrameMatrix<>::NullaryExpr(f, c, [&] { return g(rng); });
  for (Index i = 0; i < f; ++i) p.ids.push_back(1000 - 3 * i);  // any distinct ids, not 0..F-1
  if (sequences) {
    p.sequence_names = {"amazement", "pain", "anger"};
    for (Index i = 0; i < f; ++i) p.sequence.push_back(std::int32_t(i * 3 / f));
  }
  return p;
}


void check_contains(const std::string& message, const std::string& part) {
  INFO(message);
  CHECK(message.find(part) != std::string::npos);
}

}  // namespace

TEST_CASE("paired frames: write + read is exact for random sets (ids, controls, sequences)") {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 12; ++trial) {
    const Index f = 1 + trial, n = 2 + (trial * 7) % 11, m = 3 + (trial * 5) % 13, c = trial % 3;
    const auto p = random_frames(rng, f, n, m, c, trial % 2 == 0);
    const auto file = tmp("roundtrip.npz");
    data::write_paired_frames(file, p);
    const auto q = data::read_paired_frames(file, n, m);
    CHECK(q.num_frames() == f);
    CHECK(q.lowres == p.lowres);
    CHECK(q.highres == p.highres);
    CHECK(q.ids == p.ids);
    CHECK(q.num_controls() == c);
    if (c) CHECK(q.controls == p.controls);
    CHECK(q.sequence == p.sequence);
    CHECK(q.sequence_names == p.sequence_names);
    for (Index i = 0; i < f; ++i) {
      CHECK(q.lr(i) == Eigen::Map<const Points<>>(p.lowres.row(i).data(), n, 3));
      CHECK(q.hr(i).row(m - 1) == p.highres.row(i).tail(3));
    }
  }
}

TEST_CASE("paired frames: the authors' bunny file") {
  const auto file = std::filesystem::path(SIMSR_DATA_DIR) / "bunny" / "train_frames.npz";
  REQUIRE_MESSAGE(std::filesystem::exists(file), "the bundled data is missing: ", file.string());
  const auto p = data::read_paired_frames(file, 1747, 2503);
  CHECK(p.num_frames() == 256);
  CHECK(p.ids.front() == 0);
  CHECK(p.ids.back() == 255);
  CHECK(p.num_controls() == 0);
  CHECK(p.sequence.empty());
  CHECK(error_of([&] { data::read_paired_frames(file, 1748, 2503); }).find("lowres vertices") != std::string::npos);
  CHECK(error_of([&] { data::read_paired_frames(file, 1747, 2502); }).find("highres vertices") != std::string::npos);
}

TEST_CASE("paired frames: select and displacements") {
  std::mt19937 rng(5);
  const auto p = random_frames(rng, 9, 4, 6, 2, true);
  const std::vector<Index> rows{7, 2, 4};
  const auto s = p.select(rows);
  REQUIRE(s.num_frames() == 3);
  for (Index i = 0; i < 3; ++i) {
    CHECK(s.ids[std::size_t(i)] == p.ids[std::size_t(rows[std::size_t(i)])]);
    CHECK(s.lowres.row(i) == p.lowres.row(rows[std::size_t(i)]));
    CHECK(s.controls.row(i) == p.controls.row(rows[std::size_t(i)]));
    CHECK(s.sequence_name(i) == p.sequence_name(rows[std::size_t(i)]));
  }
  CHECK(!error_of([&] { p.select(std::vector<Index>{9}); }).empty());
  Points<> lr_rest = Points<>::Random(4, 3), hr_rest = Points<>::Random(6, 3);
  const auto d = data::displacements(p, lr_rest, hr_rest);
  for (Index f = 0; f < 9; ++f) {
    CHECK((d.lr(f) + lr_rest - p.lr(f)).cwiseAbs().maxCoeff() < 1e-12);
    CHECK((d.hr(f) + hr_rest - p.hr(f)).cwiseAbs().maxCoeff() < 1e-12);
  }
  CHECK(!error_of([&] { data::displacements(p, Points<>(Points<>::Zero(5, 3)), hr_rest); }).empty());
}

TEST_CASE("paired frames: one_sequence is a valid set of one named sequence, written and read back whole") {
  std::mt19937 rng(11);
  for (Index F : {1, 3, 8}) {
    auto p = data::PairedFrames<>::one_sequence(F, 4, 7, "seq_" + std::to_string(F));
    REQUIRE(p.num_frames() == F);
    CHECK(p.num_lr() == 4);
    CHECK(p.num_hr() == 7);
    CHECK(p.num_controls() == 0);
    for (Index f = 0; f < F; ++f) {
      CHECK(p.ids[std::size_t(f)] == f);
      CHECK(p.sequence_name(f) == "seq_" + std::to_string(F));
    }
    std::uniform_real_distribution<double> u(-1, 1);
    for (Index f = 0; f < F; ++f) {
      for (Index i = 0; i < 4; ++i)
        for (int c = 0; c < 3; ++c) p.lr(f)(i, c) = u(rng);
      for (Index i = 0; i < 7; ++i)
        for (int c = 0; c < 3; ++c) p.hr(f)(i, c) = u(rng);
    }
    const auto path = tmp("one_sequence_" + std::to_string(F) + ".npz");
    data::write_paired_frames(path, p);
    const auto q = data::read_paired_frames(path, 4, 7);
    CHECK(q.lowres == p.lowres);
    CHECK(q.highres == p.highres);
    CHECK(q.ids == p.ids);
    CHECK(q.sequence == p.sequence);
    CHECK(q.sequence_names == p.sequence_names);
  }
}

TEST_CASE("paired frames: every malformed file is an error naming the file and what") {
  std::mt19937 rng(7);
  const auto good = random_frames(rng, 5, 4, 6, 2, true);
  const auto file = tmp("bad.npz");
  auto write_without = [&](const std::string& drop, auto&& edit) {
    io::NpzArrays z = data::paired_frame_arrays(good);
    io::NpzArrays out;
    for (const auto& [name, a] : z)
      if (name != drop) out[name] = a;
    edit(out);
    io::write_npz(file, out);
    return error_of([&] { data::read_paired_frames(file); });
  };
  auto none = [](io::NpzArrays&) {};
  check_contains(write_without("highres", none), "no array 'highres'");
  check_contains(write_without("lowres", none), "no array 'lowres'");
  check_contains(write_without("sequence_names", none), "'sequence' and 'sequence_names'");
  check_contains(write_without("", [](io::NpzArrays& z) {
    std::vector<double> v(4 * 4 * 3, 0.0);
    z["highres"] = io::make_npy<double>({4, 4, 3}, v.data());
  }), "highres frames");
  check_contains(write_without("", [](io::NpzArrays& z) {
    std::vector<double> v(5 * 4 * 2, 0.0);
    z["lowres"] = io::make_npy<double>({5, 4, 2}, v.data());
  }), "lowres (F×V×3)");
  check_contains(write_without("", [](io::NpzArrays& z) {
    std::vector<std::int64_t> ids{1, 2, 3, 2, 5};
    z["frame"] = io::make_npy<std::int64_t>({5}, ids.data());
  }), "frame id 2 appears twice");
  check_contains(write_without("", [](io::NpzArrays& z) {
    std::vector<std::int64_t> ids{1, 2, 3};
    z["frame"] = io::make_npy<std::int64_t>({3}, ids.data());
  }), "frame (one id per frame)");
  check_contains(write_without("", [](io::NpzArrays& z) {
    std::vector<std::int32_t> s{0, 1, 2, 3, 0};
    z["sequence"] = io::make_npy<std::int32_t>({5}, s.data());
  }), "frame 3 has sequence 3");
  check_contains(write_without("", [](io::NpzArrays& z) {
    std::vector<double> c(5 * 2, 0.0);
    c[7] = std::numeric_limits<double>::infinity();
    z["controls"] = io::make_npy<double>({5, 2}, c.data());
  }), "controls frame 3, control 1 is not finite");
  // a NaN in the middle of the LR frames: frame and vertex named
  auto bad = good;
  bad.lowres(2, 3 * 1 + 2) = std::nan("");
  io::NpzArrays z = data::paired_frame_arrays(good);
  const data::FrameMatrix<> lr = bad.lowres;
  z["lowres"] = io::make_npy<double>({5, 4, 3}, lr.data());
  io::write_npz(file, z);
  check_contains(error_of([&] { data::read_paired_frames(file); }), "lowres frame 2, vertex 1 is not finite");
  check_contains(error_of([&] { data::read_paired_frames(tmp("does_not_exist.npz")); }), "does_not_exist.npz");
  check_contains(error_of([&] { data::write_paired_frames(file, bad); }), "not finite");  // nothing non-finite is written
}

TEST_CASE("splits: holdout_every partitions the rows for any size") {
  for (Index f = 0; f < 40; ++f)
    for (Index every : {0, 2, 3, 4, 7}) {
      const auto s = data::holdout_every(f, every);
      std::set<Index> all(s.train.begin(), s.train.end());
      for (Index t : s.test) {
        CHECK(t % std::max<Index>(every, 1) == 0);
        CHECK(every > 0);
        CHECK(all.insert(t).second);
      }
      CHECK(Index(all.size()) == f);
      CHECK(std::is_sorted(s.train.begin(), s.train.end()));
    }
  CHECK(!error_of([] { data::holdout_every(10, 1); }).empty());
  CHECK(!error_of([] { data::holdout_every(10, -2); }).empty());
}

TEST_CASE("splits: by sequence holds out whole performances") {
  std::mt19937 rng(11);
  const auto p = random_frames(rng, 30, 3, 3, 0, true);
  const auto s = data::by_sequence(p, {"anger", "pain"});
  CHECK(s.train.size() + s.test.size() == 30);
  for (Index t : s.test) CHECK(p.sequence_name(t) != "amazement");
  for (Index t : s.train) CHECK(p.sequence_name(t) == "amazement");
  check_contains(error_of([&] { data::by_sequence(p, {"fear"}); }), "no sequence 'fear' (the set has: amazement, pain, anger)");
  check_contains(error_of([&] { data::by_sequence(p, {"amazement", "pain", "anger"}); }), "no training frame is left");
  const auto plain = random_frames(rng, 4, 3, 3, 0, false);
  check_contains(error_of([&] { data::by_sequence(plain, {"anger"}); }), "no 'sequence' labels");
}

TEST_CASE("frame sets: one key with ids; float dtypes only; ids matched across files") {
  std::mt19937 rng(13);
  const auto p = random_frames(rng, 6, 5, 7, 0, false);
  const auto file = tmp("paired_for_set.npz");
  data::write_paired_frames(file, p);
  const auto lo = data::read_frame_set(file, "lowres", 5);
  CHECK(lo.positions == p.lowres);
  CHECK(lo.ids == p.ids);
  CHECK(lo.has_ids);
  check_contains(error_of([&] { data::read_frame_set(file, "lowres", 4); }), "lowres vertices");
  check_contains(error_of([&] { data::read_frame_set(file, "midres", 5); }), "no array 'midres'");
  data::FrameSet out;
  out.positions = p.highres.topRows(2);
  out.ids = {p.ids[3], p.ids[1]};
  const auto pred = tmp("prediction.npz");
  data::write_frame_set(pred, "highres", out);
  const auto back = data::read_frame_set(pred, "highres", 7);
  CHECK(back.positions == out.positions);
  CHECK(data::match_frame_ids(back.ids, p.ids, "truth.npz") == std::vector<Index>{3, 1});
  check_contains(error_of([&] { data::match_frame_ids({12345}, p.ids, "truth.npz"); }), "truth.npz: no frame with id 12345");
  io::NpzArrays ints;
  std::vector<std::int32_t> v(2 * 7 * 3, 1);
  ints["highres"] = io::make_npy<std::int32_t>({2, 7, 3}, v.data());
  io::write_npz(pred, ints);
  check_contains(error_of([&] { data::read_frame_set(pred, "highres", 7); }), "expected float32 or float64");
  out.positions(1, 4) = std::nan("");
  check_contains(error_of([&] { data::write_frame_set(pred, "highres", out); }), "non-finite");
}
