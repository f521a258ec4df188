// `simsr demo [--dataset face|bunny] [--out DIR]`: the paper's evaluation end to end
// (pipeline/demo.hpp): the face data (or the authors' bunny frames), the neighbourhoods, every
// baseline, the super-resolution network trained on amazement + pain and every method evaluated
// on anger + fear. Progress on stderr; Table 1 on stdout; DIR/report.json, DIR/results/
// (statistics.csv, frame_errors.csv/.svg, heatmaps.pvd), DIR/report/index.html (the page to open:
// Table 1, the plot, a 3D viewer), DIR/predictions/, DIR/network/.
// A rerun reuses the finished stages; a killed run continues (the network from its checkpoint).
// `simsr ablate` (same options): the §5.4 ablations on the same data (pipeline/ablations.hpp).
// Its own translation unit: the pipeline pulls in every area of the library.
#include <simsr/pipeline/ablations.hpp>
#include <simsr/pipeline/demo.hpp>
#include <simsr/shell/cloth_demo.hpp>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "cloth_fine_options.hpp"
#include "cloth_stepping_options.hpp"
#include "linear_solver_choice.hpp"

#ifndef SIMSR_VENDOR_DIR
#define SIMSR_VENDOR_DIR ""
#endif

namespace simsr::cli {

namespace {
struct DemoArgs {
  pipeline::DemoOptions o;
  std::string preset = "default";
  bool no_network = false;
  shell::ClothDemoOptions cloth;  ///< --dataset sheet|disk
  CLI::Option* out_given = nullptr;
  CLI::Option* epochs_given = nullptr;
  CLI::Option* seed_given = nullptr;
  CLI::Option* batch_given = nullptr;
  Index cells = 0, levels = -1, fine_cells = 0;  ///< sheet/disk: 0 / −1 / 0 the scene's default
  std::string fine_frames_from;                  ///< sheet/disk: a dataset whose fine frames this one takes
  std::string fine_target = shell::fine_target_name(shell::DetailSynthesisOptions{}.fine_target);
  std::string residual_lift = shell::residual_lift_name(shell::DetailSynthesisOptions{}.residual_lift);
  std::string linear_solver = "simplicial";  ///< sheet/disk: the data's Newton linear solver
  ClothSteppingArgs stepping;                ///< sheet/disk: --substeps, --stepping, --step-iterations
};

/// The thin-shell demo (shell/cloth_demo.hpp): progress on stderr, the tables on stdout.
int cloth_demo_cmd(DemoArgs& a) {
  shell::ClothDemoOptions& c = a.cloth;
  c.scene = shell::cloth_dataset(a.o.dataset);
  c.out = a.out_given->count() > 0 ? a.o.out : std::filesystem::path("out") / a.o.dataset;
  if (a.epochs_given->count() > 0) c.training.epochs = a.o.recipe.epochs;
  if (a.seed_given->count() > 0) c.network_seed = c.training.seed = static_cast<std::uint64_t>(a.o.recipe.seed);
  if (a.batch_given->count() > 0) c.training.batch = a.o.recipe.batch_size;
  c.data.size = shell::scene_size(c.scene, a.cells, a.levels, a.fine_cells);
  c.data.fine_frames_from = a.fine_frames_from;
  a.stepping.apply(c.data.simulation);
  c.network.fine_target = shell::parse_fine_target(a.fine_target);
  c.network.residual_lift = shell::parse_residual_lift(a.residual_lift);
  if (c.baselines == std::vector<std::string>{"none"}) c.baselines.clear();
  const auto report = with_linear_solver(a.linear_solver, [&]<class L>(LinearSolverTag<L>) {
    return shell::run_cloth_demo<L>(exec::omp, c, [](const std::string& line) { std::fprintf(stderr, "demo: %s\n", line.c_str()); });
  });
  std::cout << shell::cloth_report_text(report) << "report: " << (c.out / "report.json").string() << "; files people open: "
            << (c.out / "results" / "frame_errors.csv").string() << " and " << (c.out / "results").string() << "/*_errors.svg (per frame), " << (c.out / "results" / "compare").string()
            << "/*/ (ParaView; scripts/render_comparison.py DIR --out F.png --view oblique)\n";
  return 0;
}

int demo_cmd(DemoArgs& a) {
  if (a.o.dataset == "sheet" || a.o.dataset == "disk") return cloth_demo_cmd(a);
  a.o.face.model = scenario::face_model_preset(a.preset);
  a.o.network = !a.no_network;
  const auto report = pipeline::run_demo(exec::omp, a.o, [](const std::string& line) { std::fprintf(stderr, "demo: %s\n", line.c_str()); });
  std::cout << "Table 1 on the " << (a.o.dataset == "face" ? "test performances" : "held-out frames") << " (" << report.at("test_frames").get<Index>()
            << " frames; error = distance of each HR vertex to the truth, mesh units; bbox diagonal " << report.at("bbox_diagonal").get<double>() << ")\n\n"
            << pipeline::table1_text(report) << pipeline::lip_intersections_text(report) << "report: " << (a.o.out / "report.json").string()
            << "; files people open: " << (a.o.out / "results").string()
            << "/frame_errors.svg (browser), " << (a.o.out / "results").string() << "/heatmaps.pvd (ParaView), "
            << (a.o.out / "report" / "index.html").string() << " (browser)\n";
  return 0;
}
}  // namespace

namespace {
/// The options demo and ablate share: the data, the split, the neighbourhoods and the recipe.
void add_demo_options(CLI::App* cmd, DemoArgs& args) {
  auto* a = &args;
  auto& o = a->o;
  cmd->add_option("--dataset", o.dataset,
                  "face (simulated from the ICT kit), bunny (the authors' frames), or sheet / disk (the thin-shell paper's cloths)")
      ->check(CLI::IsMember({"face", "bunny", "sheet", "disk"}))
      ->capture_default_str();
  cmd->add_option("--data", o.data, "the shared data folder (ict_face/, bunny/)")->capture_default_str();
  a->out_given = cmd->add_option("--out", o.out, "output folder (a rerun reuses its finished stages; sheet/disk: default out/sheet, out/disk)")
                     ->capture_default_str();
  auto& cl = a->cloth;
  cmd->add_option("--sequences", cl.data.sequences, "sheet/disk: sequences to simulate (0: sheet 32, disk 16; every 5th held out)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--cells", a->cells, "sheet: coarse cells per side (8: 81 vertices); disk: rings (6: 127 vertices)")
      ->check(CLI::Range(2, 64));
  cmd->add_option("--levels", a->levels, "sheet/disk: Loop levels from the coarse to the fine cloth (3: the paper's ×64 faces)")
      ->check(CLI::Range(0, 6));
  add_fine_cloth_options(cmd, a->fine_cells, a->fine_frames_from);
  cmd->add_option("--fine-target", a->fine_target,
                  "sheet/disk: what the network's fine side holds: residual (to the subdivided coarse mesh's features) or features (the supplement)")
      ->capture_default_str()
      ->check(CLI::IsMember({"residual", "features"}));
  cmd->add_option("--residual-lift", a->residual_lift,
                  "sheet/disk: a residual target's fine rotation vectors: nearest (each the form nearest the subdivided mesh's) or own (the fine "
                  "sequence's own integer steps; the two can differ by 2 pi)")
      ->capture_default_str()
      ->check(CLI::IsMember({"nearest", "own"}));
  cmd->add_option("--linear-solver", a->linear_solver,
                  "sheet/disk: the data's Newton linear solver, simplicial (Eigen's LDLT) or cholmod (supernodal; needs CHOLMOD; the same data to "
                  "round-off, ~3x faster at the paper's 4,225 fine vertices)")
      ->capture_default_str();
  add_cloth_stepping_options(cmd, a->stepping, "sheet/disk");
  cmd->add_option("--sequence-workers", cl.data.sequence_workers,
                  "sheet/disk: sequences simulated at once, one thread each (0: OMP_NUM_THREADS; the same data for any count)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  cmd->add_option("--baseline-epochs", cl.baseline_network.epochs, "sheet/disk: epochs of the core paper's network (the network baseline)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--baselines", cl.baselines,
                  "sheet/disk: the core paper's upsampling methods evaluated beside: local_linear, network (none: neither)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--preset", a->preset, "face mesh sizes: default, paper-ratio, paper-lr")->capture_default_str();
  cmd->add_option("--frames", o.face.frames, "face: frames per performance")->capture_default_str()->check(CLI::Range(14, 100000));
  cmd->add_option("--train-sequences", o.train_sequences, "face: performances trained on")->delimiter(',')->capture_default_str();
  cmd->add_option("--test-sequences", o.test_sequences, "face: performances evaluated")->delimiter(',')->capture_default_str();
  cmd->add_option("--holdout-every", o.bunny_holdout_every, "bunny: frames f with f % n == 0 are the test frames")->capture_default_str();
  cmd->add_option("--methods", o.methods, "baselines (embedded idw rbf mls ridge local_linear beta_vae)")->delimiter(',')->capture_default_str();
  cmd->add_option("--k", o.method_parameters.k, "neighbours of the §3.2 neighbourhoods, IDW and MLS")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--rbf-distance", o.method_parameters.rbf_distance, "rbf: euclidean, geodesic or lr-mesh")->capture_default_str();
  cmd->add_option("--rbf-regularization", o.method_parameters.rbf_regularization, "rbf: lambda added to the kernel's diagonal")->capture_default_str();
  cmd->add_option("--vae-epochs", o.method_parameters.vae_epochs, "beta_vae: training epochs")->capture_default_str();
  auto& r = o.recipe;
  a->epochs_given = cmd->add_option("--epochs", r.epochs, "network: epochs (sheet/disk: default 60)")->capture_default_str();
  a->batch_given = cmd->add_option("--batch-size", r.batch_size, "network: frames per batch (sheet/disk: windows per batch, default 16)")->capture_default_str();
  cmd->add_option("--lr", r.lr, "network: Adam learning rate")->capture_default_str();
  cmd->add_option("--lr-decay-epochs", r.lr_decay_epochs, "network: halve the learning rate every n epochs (0: never)")->capture_default_str();
  cmd->add_option("--w-zreg", r.w_zreg, "network: weight of the latent regularizer (-1: the official 2)")->capture_default_str();
  cmd->add_option("--displacement-scale", r.displacement_scale, "network: multiply normalized displacements by this (1: official; 0: from the training frames)")
      ->capture_default_str();
  cmd->add_flag("--residual,!--no-residual", r.residual, "network: learn the correction of Embedded (default) or the displacement itself");
  cmd->add_option("--residual-base", r.residual_base, "network: what the residual adds to: local_linear (fitted on the training frames) or embedded")
      ->check(CLI::IsMember({"embedded", "local_linear"}))
      ->capture_default_str();
  a->seed_given = cmd->add_option("--seed", r.seed, "network: seed of the initial weights and the shuffling")->capture_default_str();
  cmd->add_flag("--without-fe", r.without_fe, "network ablation w/o FE (§5.4)");
  cmd->add_flag("--without-cu", r.without_cu, "network ablation w/o CU (§5.4)");
  cmd->add_option("--knn", r.knn, "network: EdgeConv k (default 5)");
  cmd->add_option("--upk", r.up_k, "network: interpolation neighbours (default 10; at most --k)");
  cmd->add_option("--w-contact", r.w_contact, "network: weight of the lip-contact term (0: off; face only)")->capture_default_str()->check(CLI::NonNegativeNumber);
  cmd->add_option("--contact-radius", r.contact_radius, "network: lip pairs closer than this at rest take part, and how far behind a triangle a vertex still counts (m)")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--contact-margin", r.contact_margin, "network: the clearance the contact term asks for (m; at most half a pair's rest distance)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--network-name", o.network_name,
                  "network: its name in the tables and its folder (an ablation under another name leaves the default network's stage alone)")
      ->capture_default_str();
}

int ablate_cmd(DemoArgs& a, const pipeline::AblationOptions& ab) {
  a.o.face.model = scenario::face_model_preset(a.preset);
  const auto r = pipeline::run_ablations(exec::omp, a.o, ab, [](const std::string& line) { std::fprintf(stderr, "ablate: %s\n", line.c_str()); });
  if (r.contains("table2")) std::cout << r.at("table2").get<std::string>() << "\n";
  std::cout << "variant      mean/diagonal   ms per frame\n";
  for (const auto& [name, v] : r.at("variants").items())
    std::printf("%-12s %13.4e %14.1f\n", name.c_str(), v.at("relative_mean_error").get<double>(), v.at("apply_ms_per_frame").get<double>());
  std::printf("%-12s %13.4e\nfiles: %s/ablations.csv, table2.txt, fig9_upk.svg, fig9_knn.svg (browser)\n", "Embedded",
              r.at("embedded").at("relative_mean").get<double>(), (a.o.out / "results").string().c_str());
  std::fflush(stdout);
  return 0;
}
}  // namespace

void add_demo(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("demo", "The paper's evaluation end to end: data, neighbourhoods, baselines, the network, Table 1 and the files to open");
  auto a = std::make_shared<DemoArgs>();
  a->o.vendor_dir = SIMSR_VENDOR_DIR;
  add_demo_options(cmd, *a);
  auto& o = a->o;
  cmd->add_option("--vendor-dir", o.vendor_dir, "node_modules holding three@0.147.0 for the report page (default: the build's)")->capture_default_str();
  cmd->add_option("--viewer-frames", o.viewer_frames, "frames of each test sequence the report page's viewer plays")->capture_default_str()->check(CLI::Range(1, 1000));
  cmd->add_flag("--no-network", a->no_network, "evaluate the baselines only");
  cmd->callback([&action, a] { action = [a] { return demo_cmd(*a); }; });
}

void add_ablate(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("ablate",
                                 "The §5.4 ablations on the demo's data: w/o FE, w/o CU, interpolation neighbours, EdgeConv k (Table 2, Fig. 9)");
  auto a = std::make_shared<DemoArgs>();
  auto ab = std::make_shared<pipeline::AblationOptions>();
  add_demo_options(cmd, *a);
  cmd->add_option("--ablation-epochs", ab->epochs, "epochs of every variant")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--upk-values", ab->up_k, "interpolation neighbours swept (ascending; empty: none)")->delimiter(',')->capture_default_str();
  cmd->add_option("--knn-values", ab->knn, "EdgeConv k swept (ascending; empty: none)")->delimiter(',')->capture_default_str();
  cmd->add_flag("--table2,!--no-table2", ab->table2, "train full, w/o FE and w/o CU (Table 2)");
  cmd->callback([&action, a, ab] { action = [a, ab] { return ablate_cmd(*a, *ab); }; });
}

}  // namespace simsr::cli
