// SoftDECA's data over MPI ranks (mpi/softdeca_datagen.hpp), on the level-1 ball: the 2-rank run
// writes the files a single process writes, bitwise (the wall-clock seconds aside); each rank
// simulates its block only; a rerun after a lost sample file simulates that sample alone.
#include <doctest/doctest.h>

#include <simsr/io/npz.hpp>
#include <simsr/mpi/softdeca_datagen.hpp>
#include <simsr/scenario/softdeca/sphere_template.hpp>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "../support/error_of.hpp"
#include "../support/same_arrays.hpp"

namespace mpi_test_softdeca_datagen {

using namespace simsr;
namespace fs = std::filesystem;

TEST_CASE("mpi::generate_softdeca_dataset: 2 ranks write the single process's files; a lost sample is simulated again alone") {
  const mpi::Communicator world = mpi::Communicator::world();
  REQUIRE(world.size() == 2);
  const scenario::SoftDecaTemplate tpl = scenario::sphere_softdeca_template(exec::omp, 1, 1);
  scenario::SoftDecaDatagenOptions o;
  o.samples = 5;  // rank 0: samples 0-2, rank 1: 3-4
  o.seed = 3;
  o.simulation.steps = 2;
  const fs::path root = fs::path(SIMSR_TEST_TMP_DIR) / "mpi_softdeca", ranks = root / "ranks", single = root / "single";
  if (world.is_root()) fs::remove_all(root);
  world.barrier();

  std::vector<std::string> lines;
  const auto j = mpi::generate_softdeca_dataset(exec::omp, world, tpl, "ball", o, ranks, [&](const std::string& l) { lines.push_back(l); });
  const Index mine = world.rank() == 0 ? 3 : 2;
  CHECK(std::count_if(lines.begin(), lines.end(), [](const std::string& l) { return l.rfind("sample ", 0) == 0; }) == mine);
  CHECK(j["ranks"] == 2);
  CHECK(j["simulated"] == 5);
  CHECK(j["resumed"] == 0);
  CHECK(j["kept"] == 5);
  REQUIRE(j["per_rank"].size() == 2);
  CHECK(j["per_rank"][0]["shard"]["first_sample"] == 0);
  CHECK(j["per_rank"][0]["shard"]["last_sample"] == 3);
  CHECK(j["per_rank"][1]["shard"]["first_sample"] == 3);
  CHECK(j["per_rank"][1]["simulated"] == 2);
  CHECK(j["per_sample"].size() == 5);
  CHECK(j == nlohmann::ordered_json::parse(io::detail::read_text_file(ranks / "softdeca_data.json")));  // every rank returns rank 0's summary

  if (world.is_root()) {  // the single-process run beside it
    const auto s = scenario::generate_softdeca_dataset(exec::omp, tpl, "ball", o, single);
    CHECK(s["simulated"] == 5);
    test::check_same_arrays(ranks / "softdeca_samples.npz", single / "softdeca_samples.npz");
    for (Index i = 0; i < o.samples; ++i) test::check_same_arrays(ranks / "samples" / scenario::detail::sample_file_name(i), single / "samples" / scenario::detail::sample_file_name(i));
    for (const char* f : {"template_skin.obj", "template_soft_tissue.msh", "template_muscle.msh"})
      CHECK(io::detail::read_text_file(ranks / f) == io::detail::read_text_file(single / f));
    fs::remove(ranks / "samples" / scenario::detail::sample_file_name(4));  // rank 1's: as if it was killed while simulating it
  }
  world.barrier();
  const auto again = mpi::generate_softdeca_dataset(exec::omp, world, tpl, "ball", o, ranks);
  CHECK(again["simulated"] == 1);
  CHECK(again["resumed"] == 4);
  CHECK(again["per_rank"][1]["simulated"] == 1);
  if (world.is_root()) test::check_same_arrays(ranks / "softdeca_samples.npz", single / "softdeca_samples.npz");
  world.barrier();

  scenario::SoftDecaDatagenOptions sharded = o;
  sharded.shard = {1, 2};
  CHECK(test::typed_error_of<ArgumentError>([&] { mpi::generate_softdeca_dataset(exec::omp, world, tpl, "ball", sharded, ranks); })
            .find("the options name a shard already") != std::string::npos);
}

}  // namespace mpi_test_softdeca_datagen
