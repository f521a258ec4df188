// pipeline::run_ablations (§5.4: Table 2 and Fig. 9) on a small data set in the bunny's layout:
// every variant trained once (k = 5 and upK = 10 are the full network's), each row's error equal
// to an independent evaluation of its predictions, the files written, a rerun reusing every
// variant; bad sweeps named. And the demo's lip-intersection count (write_lip_intersections)
// against the exact count frame by frame.
#include <simsr/interp/embedded.hpp>
#include <simsr/io/obj.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/pipeline/ablations.hpp>

#include "small_dataset.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

using namespace simsr;

namespace pipeline_ablations {

std::filesystem::path small_dataset(const std::string& name, Index frames) { return test::small_bunny_layout("pipeline_ablations", name, frames); }

pipeline::DemoOptions small_options(const std::filesystem::path& dir) { return test::small_demo_options(dir, 2); }

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace pipeline_ablations

using namespace pipeline_ablations;

TEST_CASE("pipeline::run_ablations: Table 2 and the sweeps, each variant trained once and evaluated independently, reused on a rerun") {
  const auto dir = small_dataset("sweep", 16);
  const auto o = small_options(dir);
  pipeline::AblationOptions a;
  a.epochs = 1;
  a.up_k = {3, 10};
  a.knn = {2, 5};
  std::vector<std::string> log;
  const auto r = pipeline::run_ablations(exec::omp, o, a, [&](const std::string& l) { log.push_back(l); });
  const auto trained = std::count_if(log.begin(), log.end(), [](const std::string& l) { return l.find(": running") != std::string::npos && l.find("network-abl_") != std::string::npos; });
  CHECK(trained == 5);  // full, wo_fe, wo_cu, upk3, knn2: upk10 and knn5 are the full network
  const auto& v = r["variants"];
  CHECK(v.size() == 7);
  CHECK(v["upk10"]["network"] == "abl_full");
  CHECK(v["knn5"]["network"] == "abl_full");
  CHECK(v["upk10"]["mean_error"] == v["full"]["mean_error"]);
  CHECK(v["wo_fe"]["recipe"]["without_fe"] == true);
  CHECK(v["upk3"]["recipe"]["up_k"] == 3);
  CHECK(v["knn2"]["recipe"]["knn"] == 2);
  for (const char* f : {"ablations.csv", "ablations.json", "table2.txt", "fig9_upk.svg", "fig9_knn.svg"})
    CHECK_MESSAGE(std::filesystem::exists(o.out / "results" / f), f);
  // every variant's error: its predictions evaluated here against the held-out truth (f % 4 == 0)
  const auto frames = data::read_paired_frames(dir / "bunny" / "train_frames.npz");
  const auto hr = io::read_obj_triangles(dir / "bunny" / "hrestshape.obj");
  for (const auto& [name, j] : v.items()) {
    const auto pred = data::read_frame_set(o.out / "predictions" / (j["network"].get<std::string>() + ".npz"), "highres", hr.V.rows());
    double sum = 0;
    Index count = 0;
    for (Index i = 0; i < pred.num_frames(); ++i) {
      const Index f = 4 * i;
      for (Index k = 0; k < hr.V.rows(); ++k) sum += (pred.frame(i).row(k) - frames.hr(f).row(k)).norm(), ++count;
    }
    CAPTURE(name);
    CHECK(j["mean_error"].get<double>() == doctest::Approx(sum / double(count)).epsilon(1e-12));
    CHECK(j["relative_mean_error"].get<double>() == doctest::Approx(sum / double(count) / r["bbox_diagonal"].get<double>()).epsilon(1e-12));
  }
  {  // Embedded's line: an independent fit on the same frames
    interp::UpsamplingProblem<> p{io::read_obj_tets(dir / "bunny" / "lrestshape.obj"), hr, {}, {}};
    interp::Embedded<> e;
    e.fit(exec::seq, p);
    double sum = 0;
    Index count = 0;
    Points<> out(p.num_hr(), 3);
    for (Index f = 0; f < frames.num_frames(); f += 4) {
      const Points<> in = frames.lr(f) - p.lr.V;
      e.apply(exec::seq, in, out);
      for (Index k = 0; k < p.num_hr(); ++k) sum += (p.hr.V.row(k) + out.row(k) - frames.hr(f).row(k)).norm(), ++count;
    }
    CHECK(r["embedded"]["mean"].get<double>() == doctest::Approx(sum / double(count)).epsilon(1e-12));
  }
  const std::string csv = read_text(o.out / "results" / "ablations.csv");
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 8);  // header + 7 variants
  CHECK(csv.find("knn5,knn,5,1,") != std::string::npos);
  const std::string table2 = read_text(o.out / "results" / "table2.txt");
  for (const char* n : {"full", "wo_fe", "wo_cu", "embedded"}) CHECK(table2.find(n) != std::string::npos);
  CHECK(read_text(o.out / "results" / "fig9_knn.svg").find("EdgeConv k") != std::string::npos);

  std::vector<std::string> again;
  const auto r2 = pipeline::run_ablations(exec::omp, o, a, [&](const std::string& l) { again.push_back(l); });
  CHECK(std::none_of(again.begin(), again.end(), [](const std::string& l) { return l.find(": running") != std::string::npos; }));
  CHECK(r2["variants"]["knn2"]["mean_error"] == v["knn2"]["mean_error"]);
}

TEST_CASE("pipeline::run_ablations: bad sweeps are named before anything trains") {
  const auto dir = small_dataset("bad", 8);
  auto o = small_options(dir);
  auto refused = [&](pipeline::AblationOptions a, const char* what) {
    CAPTURE(what);
    CHECK_THROWS_WITH_AS(pipeline::run_ablations(exec::omp, o, a), doctest::Contains(what), ArgumentError);
    CHECK(!std::filesystem::exists(o.out / "stages" / "network-abl_full.json"));
  };
  pipeline::AblationOptions base;
  base.up_k = {1, 3};
  base.knn = {1, 2};
  auto a = base;
  a.epochs = 0;
  refused(a, "epochs must be >= 1");
  a = base;
  a.up_k = {3, 11};
  refused(a, "interpolation neighbours 11 outside [1, 10]");
  a = base;
  a.up_k = {3, 3};
  refused(a, "must ascend");
  a = base;
  a.knn = {4, 2};
  refused(a, "must ascend");
  a = base;
  a.knn = {0};
  refused(a, "EdgeConv k 0");
}

TEST_CASE("pipeline demo: the lip-intersection counts of the truth and every method, frame by frame, and the contact term needs lips") {
  // the HR sphere's caps as the two patches; frames that lower the upper half push them through each other
  const auto hr = icosphere<double>(2, 1.0);
  ContactPatches caps;
  std::vector<Index> up, down;
  for (Index t = 0; t < hr.F.rows(); ++t) {
    bool all_up = true, all_down = true;
    for (Index k = 0; k < 3; ++k) all_up = all_up && hr.V(hr.F(t, k), 2) > 0.3, all_down = all_down && hr.V(hr.F(t, k), 2) < -0.3;
    if (all_up) up.push_back(t);
    if (all_down) down.push_back(t);
  }
  caps.a.resize(Index(up.size()), 3);
  caps.b.resize(Index(down.size()), 3);
  for (std::size_t i = 0; i < up.size(); ++i) caps.a.row(Index(i)) = hr.F.row(up[i]);
  for (std::size_t i = 0; i < down.size(); ++i) caps.b.row(Index(i)) = hr.F.row(down[i]);
  pipeline::DemoData d;
  d.lips = caps;
  const Index F = 6, M = hr.V.rows();
  d.test.highres.resize(F, 3 * M);
  d.test.lowres.resize(F, 3);
  std::vector<data::FrameSet> predictions(2);
  for (auto& p : predictions) p.positions.resize(F, 3 * M);
  for (Index f = 0; f < F; ++f) {
    d.test.ids.push_back(10 + f);
    d.test_names.push_back(f < 3 ? "anger" : "fear");
    for (Index v = 0; v < M; ++v) {
      const Vec3<> x = hr.V.row(v).transpose();
      // the upper hemisphere lowered by dz: from about 0.6 down, its cap cuts through the lower one
      auto lowered = [&](double dz) { return Vec3<>(x[0], x[1], x[2] > 0 ? x[2] - dz : x[2]); };
      const Vec3<> t = lowered(0.0), a = lowered(f % 2 ? 0.8 : 0.1), b = lowered(0.2 * double(f));
      for (Index k = 0; k < 3; ++k) d.test.highres(f, 3 * v + k) = t[k], predictions[0].positions(f, 3 * v + k) = a[k], predictions[1].positions(f, 3 * v + k) = b[k];
    }
  }
  const auto csv = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "pipeline_ablations" / "lips.csv";
  const auto j = pipeline::detail::write_lip_intersections(exec::omp, csv, d, {"m0", "m1"}, predictions);
  const auto truth = eval::intersecting_pairs_per_frame(exec::seq, d.test.highres, caps);
  const auto m0 = eval::intersecting_pairs_per_frame(exec::seq, predictions[0].positions, caps);
  const auto m1 = eval::intersecting_pairs_per_frame(exec::seq, predictions[1].positions, caps);
  CHECK(std::all_of(truth.begin(), truth.end(), [](auto c) { return c == 0; }));
  CHECK(m0[1] > 0);  // lowered through
  CHECK(m0[0] == 0);
  CHECK(j["methods"]["truth"]["pairs_total"] == 0);
  CHECK(j["methods"]["m0"]["frames_with_intersections"] == 3);
  std::int64_t total1 = 0;
  for (auto c : m1) total1 += c;
  CHECK(j["methods"]["m1"]["pairs_total"] == total1);
  const std::string text = read_text(csv);
  CHECK(text.rfind("frame,sequence,truth,m0,m1\n", 0) == 0);
  CHECK(text.find("11,anger,0," + std::to_string(m0[1]) + "," + std::to_string(m1[1]) + "\n") != std::string::npos);
  nlohmann::ordered_json report;
  report["lip_intersections"] = j;
  CHECK(pipeline::lip_intersections_text(report).find("m0") != std::string::npos);

  // the bunny has no lips: the contact term is refused, naming why
  const auto dir = small_dataset("no_lips", 8);
  auto o = small_options(dir);
  o.methods = {"embedded"};
  o.recipe.epochs = 1;
  o.recipe.w_contact = 1.0;
  CHECK_THROWS_WITH_AS(pipeline::run_demo(exec::omp, o), doctest::Contains("needs contact patches"), ArgumentError);
}
