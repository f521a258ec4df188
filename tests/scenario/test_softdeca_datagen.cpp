// SoftDECA's datagen leaves out, and reports, the samples no solver converges: their
// .failed.json files, the summary's list, the dataset's sample_index; a rerun keeps the verdict;
// another run's failed file is refused; --stop-on-unconverged stops. On the level-1 ball.
#include <doctest/doctest.h>

#include <simsr/io/npz.hpp>
#include <simsr/scenario/softdeca/softdeca_datagen.hpp>
#include <simsr/scenario/softdeca/sphere_template.hpp>

#include <algorithm>
#include <filesystem>
#include <vector>

#include "../support/same_arrays.hpp"

namespace scenario_test_softdeca_datagen {

using namespace simsr;
using namespace simsr::scenario;
namespace fs = std::filesystem;

// exec::seq throughout: the TSan build leaves it out (tests/CMakeLists.txt, "single-threaded").
TEST_CASE("generate_softdeca_dataset: unconverged samples are left out and listed, the rest kept exactly" *
          doctest::test_suite("single-threaded")) {
  const SoftDecaTemplate tpl = sphere_softdeca_template(exec::seq, 1, 1);
  SoftDecaDatagenOptions o;
  o.samples = 4;
  o.seed = 4;
  o.simulation.steps = 1;
  o.simulation.newton_fallback = false;  // a capped local-global solve is then a ConvergenceError
  // each sample's largest local-global solve, uncapped; the cap is their median, so some pass and some fail
  std::vector<Index> largest;
  std::vector<Points<>> skins;
  SoftDecaSimulator sim(tpl);
  const Index E = tpl.expression_deltas.rows();
  for (Index i = 0; i < o.samples; ++i) {
    const SoftDecaResult r = sim.simulate(exec::seq, sample_softdeca_parameters(o.seed, std::uint64_t(i)),
                                          sample_expression_weights(o.seed, std::uint64_t(i), E, E), o.simulation);
    largest.push_back(*std::max_element(r.iterations.begin(), r.iterations.end()));
    skins.push_back(r.skin);
  }
  std::vector<Index> sorted = largest;
  std::sort(sorted.begin(), sorted.end());
  o.simulation.max_iterations = sorted[sorted.size() / 2 - 1];
  std::vector<Index> pass, fail;
  for (Index i = 0; i < o.samples; ++i) (largest[std::size_t(i)] <= o.simulation.max_iterations ? pass : fail).push_back(i);
  REQUIRE(!pass.empty());
  REQUIRE(!fail.empty());

  const fs::path dir = fs::path(SIMSR_TEST_TMP_DIR) / "softdeca_datagen_failed";
  fs::remove_all(dir);
  std::vector<std::string> lines;
  const auto j = generate_softdeca_dataset(exec::seq, tpl, "ball", o, dir, [&](const std::string& l) { lines.push_back(l); });
  CHECK(j["kept"] == Index(pass.size()));
  CHECK(j["failed_samples"].get<std::vector<Index>>() == fail);
  for (Index i : fail) CHECK(fs::exists(dir / "samples" / scenario::detail::sample_file_name(i, ".failed.json")));
  for (Index i : pass) CHECK(fs::exists(dir / "samples" / scenario::detail::sample_file_name(i)));
  CHECK(std::count_if(lines.begin(), lines.end(), [](const std::string& l) { return l.find("left out") != std::string::npos; }) ==
        std::ptrdiff_t(fail.size()) + 1);  // one per failed sample, one summary line
  const io::NpzArrays z = io::read_npz(dir / "softdeca_samples.npz");
  const auto index = z.at("sample_index").to_matrix<std::int64_t>();
  REQUIRE(index.size() == Index(pass.size()));
  for (std::size_t k = 0; k < pass.size(); ++k) {
    CHECK(index(Index(k)) == pass[k]);
    CHECK(z.at("skin").frame_points(Index(k)) == skins[std::size_t(pass[k])]);  // the same iterates as uncapped: bit for bit
  }
  CHECK(read_softdeca_dataset(dir).size() == Index(pass.size()));

  // a rerun keeps the verdicts and simulates nothing
  const auto again = generate_softdeca_dataset(exec::seq, tpl, "ball", o, dir);
  CHECK(again["simulated"] == 0);
  CHECK(again["failed_samples"] == j["failed_samples"]);
  // a failed file of another run (another seed's fingerprint) is refused, naming it
  SoftDecaDatagenOptions other = o;
  other.seed = 5;
  const fs::path dir2 = fs::path(SIMSR_TEST_TMP_DIR) / "softdeca_datagen_failed_other";
  fs::remove_all(dir2);
  fs::create_directories(dir2 / "samples");
  fs::copy_file(dir / "samples" / scenario::detail::sample_file_name(fail[0], ".failed.json"), dir2 / "samples" / scenario::detail::sample_file_name(fail[0], ".failed.json"));
  try {
    generate_softdeca_dataset(exec::seq, tpl, "ball", other, dir2);
    FAIL("another run's failed file was accepted");
  } catch (const Error& e) {
    CHECK(std::string(e.what()).find(scenario::detail::sample_file_name(fail[0], ".failed.json")) != std::string::npos);
  }
  // asked to stop, the first unconverged sample is an error naming it
  SoftDecaDatagenOptions strict = o;
  strict.skip_unconverged = false;
  const fs::path dir3 = fs::path(SIMSR_TEST_TMP_DIR) / "softdeca_datagen_failed_strict";
  fs::remove_all(dir3);
  try {
    generate_softdeca_dataset(exec::seq, tpl, "ball", strict, dir3);
    FAIL("an unconverged sample did not stop the run");
  } catch (const Error& e) {
    CHECK(std::string(e.what()).find("sample " + std::to_string(fail[0])) != std::string::npos);
  }
}

TEST_CASE("generate_softdeca_dataset: shards one after another, then the whole run, write the whole run's files; a shard writes no data set" *
          doctest::test_suite("single-threaded")) {
  const SoftDecaTemplate tpl = sphere_softdeca_template(exec::seq, 1, 1);
  SoftDecaDatagenOptions o;
  o.samples = 5;
  o.seed = 2;
  o.simulation.steps = 1;
  const fs::path whole = fs::path(SIMSR_TEST_TMP_DIR) / "softdeca_datagen_whole", parts = fs::path(SIMSR_TEST_TMP_DIR) / "softdeca_datagen_shards";
  fs::remove_all(whole);
  fs::remove_all(parts);
  generate_softdeca_dataset(exec::seq, tpl, "ball", o, whole);
  Index simulated = 0;
  for (Index k = 0; k < 3; ++k) {  // blocks of 2, 2, 1 samples
    SoftDecaDatagenOptions s = o;
    s.shard = {k, 3};
    const auto part = generate_softdeca_dataset(exec::seq, tpl, "ball", s, parts);
    CHECK(part["shard"]["first_sample"] == (k == 0 ? 0 : k == 1 ? 2 : 4));
    CHECK(part["shard"]["last_sample"] == (k == 0 ? 2 : k == 1 ? 4 : 5));
    simulated += part["simulated"].get<Index>();
    CHECK_FALSE(fs::exists(parts / "softdeca_samples.npz"));
    CHECK(fs::exists(parts / "template_skin.obj"));  // shard 0 wrote it
  }
  CHECK(simulated == 5);
  const auto j = generate_softdeca_dataset(exec::seq, tpl, "ball", o, parts);
  CHECK(j["simulated"] == 0);
  CHECK(j["resumed"] == 5);
  test::check_same_arrays(whole / "softdeca_samples.npz", parts / "softdeca_samples.npz");
  SoftDecaDatagenOptions bad = o;
  bad.shard = {3, 3};
  CHECK_THROWS_AS(generate_softdeca_dataset(exec::seq, tpl, "ball", bad, parts), ArgumentError);
}

}  // namespace scenario_test_softdeca_datagen
