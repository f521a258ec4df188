// Data-parallel training (issue #16) without MPI: R ranks as threads (test::ThreadBatchGroups).
// The run's weights, BatchNorm statistics, Adam moments and losses must not depend on R, bit for
// bit, in float and in double; the split path's gradient must be the whole batch's gradient.
#include "../support/thread_batch_group.hpp"
#include "batch_split_fixture.hpp"

#include <simsr/nn/trainer.hpp>

#include <doctest/doctest.h>

#include <cstring>
#include <filesystem>
#include <functional>

#include "../support/scratch_dir.hpp"

using namespace simsr;
using nn::Matrix;

namespace {

using namespace simsr::test;

/// body(rank, group) on one process (group nullptr) or on `ranks` threads.
void on_ranks(int ranks, const std::function<void(int, nn::BatchGroup*)>& body) {
  if (ranks == 1) return body(0, nullptr);
  test::ThreadBatchGroups groups(ranks);
  groups.run([&](int r, nn::BatchGroup& g) { body(r, &g); });
}

/// The run on `ranks` ranks; every rank's state.
template <class S>
std::vector<RunState<S>> run_ranks(const Problem<S>& p, int ranks, Index epochs) {
  std::vector<RunState<S>> out(static_cast<std::size_t>(ranks));
  on_ranks(ranks, [&](int r, nn::BatchGroup* g) {
    nn::Rng init(5);
    nn::SuperResolutionNet<S> net(p.cfg, p.geo, init);
    nn::Trainer<S> tr(net, p.faces, p.frames, options(epochs, g));
    tr.set_holdout(p.holdout);
    tr.run(exec::seq);
    out[std::size_t(r)] = state_of(net, tr);
  });
  return out;
}

template <class S>
void check_rank_counts(nn::NetworkConfig base, Index F, Index batch, std::vector<int> rank_counts, const std::string& what) {
  const Problem<S> p = make_problem<S>(std::move(base), 3, F, batch);
  const RunState<S> one = run_ranks<S>(p, 1, 2).at(0);
  for (int R : rank_counts) {
    const auto all = run_ranks<S>(p, R, 2);
    for (int r = 0; r < R; ++r) check_same(all[std::size_t(r)], one, what + ": " + std::to_string(R) + " ranks, rank " + std::to_string(r) + " vs 1 process");
  }
}

}  // namespace

TEST_CASE("nn::Trainer with a batch split: 2 and 3 ranks give the single process's bits, in double and in float") {
  // 9 frames in batches of 3: every rank count splits every batch; 10 in batches of 4: 4, 4, 2
  check_rank_counts<double>(nn::NetworkConfig::official(), 9, 3, {2, 3}, "official, double");
  check_rank_counts<float>(nn::NetworkConfig::official(), 9, 3, {2, 3}, "official, float");
  check_rank_counts<double>(nn::NetworkConfig::official(), 10, 4, {2}, "official, double, uneven last batch");
  nn::NetworkConfig paper = nn::NetworkConfig::paper();  // ramped latent norm, sums per item
  check_rank_counts<double>(paper, 9, 3, {2, 3}, "paper, double");
  nn::NetworkConfig drop = nn::NetworkConfig::official();
  drop.dropout = 0.3;  // each item's mask from its own stream: the same on any rank
  check_rank_counts<float>(drop, 9, 3, {2}, "official with dropout, float");
}

TEST_CASE("nn::Trainer with a batch split: a checkpoint of 2 ranks resumes on 1 and on 3 as the uninterrupted run") {
  const test::ScratchDir dir("batch_split_resume");
  std::filesystem::create_directories(dir.path);
  const Problem<double> p = make_problem<double>(nn::NetworkConfig::official(), 4, 9, 3);
  const RunState<double> whole = run_ranks<double>(p, 1, 3).at(0);
  const auto ckpt = dir.path / "two.npz";
  on_ranks(2, [&](int, nn::BatchGroup* g) {
    nn::Rng init(5);
    nn::SuperResolutionNet<double> net(p.cfg, p.geo, init);
    nn::Trainer<double> tr(net, p.faces, p.frames, options(3, g));
    tr.set_holdout(p.holdout);
    tr.run_epoch(exec::seq);
    tr.save_checkpoint(ckpt, nn::ModelData{p.cfg, p.geo, {}, p.faces});  // rank 0 writes
  });
  REQUIRE(std::filesystem::exists(ckpt));
  for (int R : {1, 3}) {
    std::vector<RunState<double>> out(static_cast<std::size_t>(R));
    on_ranks(R, [&](int r, nn::BatchGroup* g) {
      nn::Rng init(99);  // other initial weights: the checkpoint replaces them
      nn::SuperResolutionNet<double> net(p.cfg, p.geo, init);
      nn::Trainer<double> tr(net, p.faces, p.frames, options(3, g));
      tr.set_holdout(p.holdout);
      tr.load_checkpoint(ckpt);
      tr.run(exec::seq);
      out[std::size_t(r)] = state_of(net, tr);
    });
    for (int r = 0; r < R; ++r) {
      RunState<double> got = out[std::size_t(r)];
      RunState<double> want = whole;
      want.losses.erase(want.losses.begin(), want.losses.begin() + 5);  // the resumed run reports epochs 2 and 3
      check_same(got, want, "resumed on " + std::to_string(R) + " ranks, rank " + std::to_string(r));
    }
  }
}

TEST_CASE("nn::BatchSplit: the split path's gradient is the whole batch's (double, every loss profile)") {
  for (const char* profile : {"official", "paper"}) {
    CAPTURE(profile);
    const Problem<double> p = make_problem<double>(nn::NetworkConfig::preset(profile), 8, 5, 5);
    nn::Rng init(5);
    nn::SuperResolutionNet<double> net(p.cfg, p.geo, init);
    nn::SuperResolutionLoss<double> loss(p.cfg, net.hr_rest_normalized(), p.faces, 100);
    Matrix<double> pred, d_pred, d_z;
    auto gradient = [&](nn::BatchSplit* split, double& total) {
      net.set_batch_split(split);
      loss.set_batch_split(split);
      net.store().zero_grad();
      net.forward(exec::seq, nn::Mode::train, p.frames.ldx, pred);
      total = loss.evaluate(exec::seq, pred, p.frames.hdx, net.code(), 40, &d_pred, &d_z).total;
      net.backward(exec::seq, d_pred, &d_z);
      net.set_batch_split(nullptr);
      loss.set_batch_split(nullptr);
      const auto g = net.store().gradients();
      return std::vector<double>(g.data(), g.data() + g.size());
    };
    const auto bufs = net.store().buffers();
    const std::vector<double> buffers0(bufs.data(), bufs.data() + bufs.size());
    double plain_total = 0, split_total = 0;
    const auto plain = gradient(nullptr, plain_total);
    auto b = net.store().buffers();
    std::copy(buffers0.begin(), buffers0.end(), b.data());  // the same running statistics before the second forward
    nn::BatchSplit split;
    split.set_batch(5);
    const auto split_g = gradient(&split, split_total);
    CHECK(split_total == doctest::Approx(plain_total).epsilon(1e-12));
    double max_diff = 0, max_abs = 0;
    for (std::size_t i = 0; i < plain.size(); ++i) {
      max_diff = std::max(max_diff, std::abs(plain[i] - split_g[i]));
      max_abs = std::max(max_abs, std::abs(plain[i]));
    }
    CHECK(max_abs > 0);
    CHECK(max_diff <= 1e-12 * max_abs);
  }
}

TEST_CASE("nn::BatchSplit: refusals name what is wrong") {
  test::ThreadBatchGroups groups(3);
  nn::BatchSplit split(&groups.member(1));
  CHECK_THROWS_WITH_AS(split.set_batch(2), doctest::Contains("a batch of 2 items cannot be split over 3 ranks"), ArgumentError);
  split.set_batch(7);  // blocks 3, 2, 2: rank 1 holds items 3, 4
  CHECK(split.first() == 3);
  CHECK(split.count() == 2);
  CHECK_THROWS_AS(split.rows_per_item(5, "here"), ShapeError);
  CHECK(split.rows_per_item(8, "here") == 4);
  // a trainer whose last batch is smaller than the ranks is refused before training
  const Problem<double> p = make_problem<double>(nn::NetworkConfig::official(), 1, 10, 4);  // batches 4, 4, 2
  nn::Rng init(5);
  nn::SuperResolutionNet<double> net(p.cfg, p.geo, init);
  CHECK_THROWS_WITH_AS(nn::Trainer<double>(net, p.faces, p.frames, options(1, &groups.member(0))),
                       doctest::Contains("end with a batch of 2"), ArgumentError);
  // f_θ's rows are split in min(32, M) groups: more ranks than groups (M = 24 here) are refused
  test::ThreadBatchGroups many(25);
  nn::BatchSplit wide(&many.member(0));
  CHECK_THROWS_WITH_AS(net.set_batch_split(&wide), doctest::Contains("split in 24 groups of HR vertices, at most 24 ranks; got 25"), ArgumentError);
}

TEST_CASE("nn::BatchSplit::set_items: unequal items, item-aligned chunks over this rank's rows, rows gathered in item order") {
  const std::vector<Index> rows = {5, 3, 7, 4, 6};  // 3 ranks: items {0, 1}, {2, 3}, {4}
  std::vector<std::vector<double>> gathered(3);
  std::vector<Index> begin(3), local(3), total(3);
  std::vector<std::vector<std::pair<Index, Index>>> ranges(3);
  test::ThreadBatchGroups groups(3);
  groups.run([&](int r, nn::BatchGroup& g) {
    nn::BatchSplit s(&g);
    s.set_items(rows);
    begin[std::size_t(r)] = s.local_row_begin();
    local[std::size_t(r)] = s.local_rows();
    total[std::size_t(r)] = s.total_rows(s.local_rows(), "test");
    const auto c = s.chunks(s.local_rows(), 7, "test");  // ⌈7/5⌉ = 2 chunks per item
    for (Index i = 0; i < c.count(); ++i) ranges[std::size_t(r)].push_back(c.range(i));
    std::vector<double> mine(std::size_t(s.local_rows()));
    for (Index i = 0; i < s.local_rows(); ++i) mine[std::size_t(i)] = double(s.local_row_begin() + i);
    const double* all = s.gather_rows(mine.data(), 1);
    gathered[std::size_t(r)].assign(all, all + 25);
  });
  CHECK(begin == std::vector<Index>{0, 8, 19});
  CHECK(local == std::vector<Index>{8, 11, 6});
  CHECK(total == std::vector<Index>{25, 25, 25});
  // rank 1: item 2 (7 rows: 4 + 3), item 3 (4 rows: 2 + 2), local row numbers
  CHECK(ranges[1] == std::vector<std::pair<Index, Index>>{{0, 4}, {4, 7}, {7, 9}, {9, 11}});
  for (int r = 0; r < 3; ++r) {
    CAPTURE(r);
    for (Index i = 0; i < 25; ++i) CHECK(gathered[std::size_t(r)][std::size_t(i)] == double(i));
  }
  nn::BatchSplit one;
  CHECK_THROWS_AS(one.set_items({3, 0, 2}), ArgumentError);
  one.set_items({3, 4});
  CHECK_THROWS_AS(one.total_rows(6, "here"), ShapeError);
}
