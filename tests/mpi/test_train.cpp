// Data-parallel training over MPI (mpi::MpiBatchGroup, nn::Trainer's group): the 2-rank run ends
// with the single process's weights, BatchNorm statistics, Adam moments and losses, bit for bit,
// in double and in float; both ranks hold the same state; only rank 0 writes a checkpoint.
#include <doctest/doctest.h>

#include <simsr/mpi/batch_group.hpp>

#include <filesystem>

#include "../nn/batch_split_fixture.hpp"

namespace mpi_test_train {

using namespace simsr;
namespace fs = std::filesystem;

template <class S>
test::RunState<S> train(const test::Problem<S>& p, nn::BatchGroup* group, Index epochs, const fs::path& checkpoint = {}) {
  nn::Rng init(5);
  nn::SuperResolutionNet<S> net(p.cfg, p.geo, init);
  nn::Trainer<S> tr(net, p.faces, p.frames, test::options(epochs, group));
  tr.set_holdout(p.holdout);  // 2 frames: one per rank
  tr.run(exec::omp);
  if (!checkpoint.empty()) tr.save_checkpoint(checkpoint, nn::ModelData{p.cfg, p.geo, {}, p.faces});
  return test::state_of(net, tr);
}

template <class S>
void check_two_ranks(nn::NetworkConfig base, Index F, Index batch, const std::string& what) {
  const mpi::Communicator world = mpi::Communicator::world();
  REQUIRE(world.size() == 2);
  mpi::MpiBatchGroup group(world);
  const test::Problem<S> p = test::make_problem<S>(std::move(base), 6, F, batch);
  const test::RunState<S> ranks = train<S>(p, &group, 2);
  const test::RunState<S> single = train<S>(p, nullptr, 2);  // this process alone, no collective
  test::check_same(ranks, single, what + ": rank " + std::to_string(world.rank()) + " of 2 vs 1 process");
  // both ranks hold the same weights: rank 1's gathered on rank 0
  const auto all = world.allgather(ranks.values);
  CHECK(test::same_bits(all[0], all[1]));
}

TEST_CASE("mpi::MpiBatchGroup: training on 2 ranks gives the single process's bits (double and float); rank 0 alone writes") {
  check_two_ranks<double>(nn::NetworkConfig::official(), 9, 3, "official, double");
  check_two_ranks<float>(nn::NetworkConfig::official(), 10, 4, "official, float, batches 4, 4, 2");
  check_two_ranks<double>(nn::NetworkConfig::paper(), 9, 3, "paper, double");

  const mpi::Communicator world = mpi::Communicator::world();
  mpi::MpiBatchGroup group(world);
  const fs::path dir = fs::path(SIMSR_TEST_TMP_DIR) / "mpi_train", ckpt = dir / ("ckpt_" + std::to_string(world.rank()) + ".npz");
  if (world.is_root()) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  world.barrier();
  train<double>(test::make_problem<double>(nn::NetworkConfig::official(), 2, 6, 3), &group, 1, ckpt);
  world.barrier();
  CHECK(fs::exists(dir / "ckpt_0.npz"));
  CHECK(!fs::exists(dir / "ckpt_1.npz"));
}

}  // namespace mpi_test_train
