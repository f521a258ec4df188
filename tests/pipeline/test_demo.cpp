// pipeline::run_demo on a small data set in the bunny's layout (an LR box, an HR sphere inside
// it, frames of a 6-parameter smooth motion): every file it promises, Table 1 against an
// independent evaluation, stages reused on a rerun, one new method run alone, and a network
// whose marker is gone (a killed run) resumed from its checkpoint to the same numbers.
#include <simsr/interp/embedded.hpp>
#include <simsr/io/obj.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/pipeline/demo.hpp>

#include "small_dataset.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

using namespace simsr;

namespace pipeline_demo {

std::filesystem::path small_dataset(const std::string& name, Index frames) { return test::small_bunny_layout("pipeline_demo", name, frames); }

pipeline::DemoOptions small_options(const std::filesystem::path& dir) {
  auto o = test::small_demo_options(dir, 5);
  o.methods = {"embedded", "idw", "ridge"};
  o.recipe.epochs = 1;
  return o;
}

struct Run {
  nlohmann::ordered_json report;
  std::vector<std::string> log;
  Index count(const std::string& what) const {
    return Index(std::count_if(log.begin(), log.end(), [&](const std::string& l) { return l.find(what) != std::string::npos; }));
  }
};

Run run(const pipeline::DemoOptions& o) {
  Run r;
  r.report = pipeline::run_demo(exec::omp, o, [&](const std::string& l) { r.log.push_back(l); });
  return r;
}

double mean_of(const nlohmann::ordered_json& report, const std::string& method) { return report["table1"][method]["raw"]["mean"].get<double>(); }

TEST_CASE("pipeline::run_demo: every file, Table 1 checked independently, reuse, resume") {
  const auto dir = small_dataset("full", 24);
  auto o = small_options(dir);
  const Run first = run(o);
  const auto& rep = first.report;
  CHECK(rep["train_frames"] == 18);
  CHECK(rep["test_frames"] == 6);
  for (const char* f : {"report.json", "neighbors.npz", "results/statistics.csv", "results/frame_errors.csv", "results/frame_errors.svg", "results/heatmaps.pvd",
                        "predictions/embedded.npz", "predictions/idw.npz", "predictions/ridge.npz", "predictions/network.npz", "network/model.npz",
                        "network/checkpoint.npz", "network/training_history.csv"})
    CHECK_MESSAGE(std::filesystem::exists(o.out / f), f);
  std::vector<std::string> names;
  for (const auto& [name, m] : rep["table1"].items()) names.push_back(name);
  // Fig. 6's views: one folder (the one test "sequence" of the bunny layout) with the LR input,
  // the truth and every method's surface; truth's error is 0, each method's its distance.
  REQUIRE(rep["comparison_views"].size() == 1);
  const auto views = o.out / "results" / "compare" / rep["comparison_views"][0].get<std::string>();
  for (const char* f : {"lr_input.vtu", "truth.vtu", "embedded.vtu", "idw.vtu", "ridge.vtu", "network.vtu"}) CHECK_MESSAGE(std::filesystem::exists(views / f), f);
  CHECK(names == std::vector<std::string>{"embedded", "idw", "ridge", "network"});

  // Embedded's Table-1 mean recomputed here: its prediction of every held-out frame (f % 4 == 0).
  {
    interp::UpsamplingProblem<> p{io::read_obj_tets(dir / "bunny" / "lrestshape.obj"), io::read_obj_triangles(dir / "bunny" / "hrestshape.obj"), {}, {}};
    const auto frames = data::read_paired_frames(dir / "bunny" / "train_frames.npz");
    interp::Embedded<> e;
    e.fit(exec::seq, p);
    double sum = 0, largest = 0;
    Index count = 0;
    Points<> out(p.num_hr(), 3);
    for (Index f = 0; f < frames.num_frames(); f += 4) {
      const Points<> in = frames.lr(f) - p.lr.V;
      e.apply(exec::seq, in, out);
      for (Index v = 0; v < p.num_hr(); ++v) {
        const double d = (p.hr.V.row(v) + out.row(v) - frames.hr(f).row(v)).norm();
        sum += d, largest = std::max(largest, d), ++count;
      }
    }
    CHECK(mean_of(rep, "embedded") == doctest::Approx(sum / double(count)).epsilon(1e-12));
    CHECK(rep["table1"]["embedded"]["raw"]["max"].get<double>() == doctest::Approx(largest).epsilon(1e-12));
    const double diag = rep["bbox_diagonal"].get<double>();
    CHECK(rep["table1"]["embedded"]["relative"]["mean"].get<double>() == doctest::Approx(sum / double(count) / diag).epsilon(1e-12));
  }
  // The motion is a 6-parameter linear family: ridge (over Embedded) recovers it.
  CHECK(mean_of(rep, "ridge") < 1e-6 * mean_of(rep, "embedded"));
  // Normalized to the largest: the largest mean is 1, every other below.
  double top = 0;
  for (const auto& [name, m] : rep["table1"].items()) top = std::max(top, m["normalized"]["mean"].get<double>());
  CHECK(top == doctest::Approx(1.0));
  CHECK(pipeline::table1_text(rep).find("ridge") != std::string::npos);

  SUBCASE("a rerun reuses every stage and gives the same table") {
    const Run again = run(o);
    CHECK(again.count("reused") == 5);  // neighbors, 3 methods, network
    CHECK(again.count("running") == 0);
    for (const auto& name : names) CHECK(mean_of(again.report, name) == mean_of(rep, name));
  }
  SUBCASE("a method added later runs alone") {
    o.methods.push_back("mls");
    const Run more = run(o);
    CHECK(more.count("reused") == 5);
    CHECK(more.count("stage method-mls: running") == 1);
    CHECK(more.report["table1"].contains("mls"));
    CHECK(mean_of(more.report, "ridge") == mean_of(rep, "ridge"));
  }
  SUBCASE("changed network options retrain the network only") {
    o.recipe.seed = 6;
    const Run other = run(o);
    CHECK(other.count("reused") == 4);
    CHECK(other.count("stage network-network: its options or inputs changed") == 1);
    CHECK(mean_of(other.report, "network") != mean_of(rep, "network"));
    CHECK(mean_of(other.report, "embedded") == mean_of(rep, "embedded"));
  }
  SUBCASE("a killed network stage resumes from its checkpoint to the same numbers") {
    std::filesystem::remove(o.out / "stages" / "network-network.json");
    const Run resumed = run(o);
    CHECK(resumed.count("resuming") == 1);
    CHECK(mean_of(resumed.report, "network") == mean_of(rep, "network"));
  }
}

TEST_CASE("pipeline::run_demo: bad options are named") {
  const auto dir = small_dataset("errors", 8);
  auto o = small_options(dir);
  o.dataset = "cat";
  CHECK_THROWS_AS(pipeline::run_demo(exec::omp, o), ArgumentError);
  o = small_options(dir);
  o.methods = {"embedded", "spline"};
  o.network = false;
  try {
    pipeline::run_demo(exec::omp, o);
    FAIL("no error");
  } catch (const ArgumentError& e) {
    CHECK(std::string(e.what()).find("spline") != std::string::npos);
  }
  o = small_options(dir);
  o.methods.clear();
  o.network = false;
  CHECK_THROWS_AS(pipeline::run_demo(exec::omp, o), ArgumentError);
  for (const std::string bad : {"", "../x", "a b", "ridge", "data", "report"}) {
    o = small_options(dir);
    o.network_name = bad;
    CAPTURE(bad);
    CHECK_THROWS_WITH_AS(pipeline::run_demo(exec::omp, o), doctest::Contains("network name"), ArgumentError);
  }
  o = small_options(dir);
  o.bunny_holdout_every = 1;
  CHECK_THROWS_AS(pipeline::run_demo(exec::omp, o), ArgumentError);
}

}  // namespace pipeline_demo
