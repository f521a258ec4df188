// compare_methods: every super-resolution method of simsr through one function template,
// each one type away from the next (issue #10). On a paired data set (the authors' bunny by
// default) it holds out every n-th frame, fits each method on the rest shapes, trains the ones
// that learn from frames on the others, and prints one JSON line per method: Table-1 statistics
// relative to the bounding-box diagonal, seconds per frame, fit + training seconds.
//
//   compare_methods                              # ../shared/data/bunny, every 4th frame held out
//   compare_methods --epochs 14 --vae-epochs 4   # the network and the β-VAE trained longer
//   compare_methods --train-frames 16 --test-frames 8 --epochs 1 --vae-epochs 1   # a quick run
#include <simsr/data/data.hpp>
#include <simsr/eval/evaluate.hpp>
#include <simsr/interp/interp.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <iostream>
#include <string>

#include "../simsr/errors.hpp"

namespace {

using namespace simsr;

struct Data {
  interp::UpsamplingProblem<> problem;
  data::PairedFrames<> train, test;
};

/// `method` through the same fit/train/evaluate code as every other; `options` are its training
/// options when it learns from frames.
template <interp::Interpolator Method, class... Options>
void run(const std::string& name, Method& method, Data& d, const Options&... options) {
  const eval::Evaluation r = eval::run_method(exec::omp, method, d.problem, d.train, d.test, options...);
  const auto s = r.errors.relative_statistics();
  nlohmann::ordered_json j;
  j["method"] = name;
  j["trainable"] = interp::TrainableInterpolator<Method>;
  j["needs_neighborhoods"] = interp::needs_neighborhoods_v<Method>;
  j["relative_error"] = {{"mean", s.mean}, {"median", s.median}, {"std", s.std}, {"max", s.max}, {"min", s.min}};
  j["seconds_per_frame"] = r.seconds_per_frame;
  j["fit_and_train_seconds"] = r.prepare_seconds;
  std::cout << j.dump() << std::endl;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Every simsr interpolator on one paired data set, through one function template"};
  std::string dir = SIMSR_DEFAULT_DATA "/bunny";
  Index holdout = 4, train_frames = -1, test_frames = -1, epochs = 14, vae_epochs = 4;
  app.add_option("--data-dir", dir, "folder with lrestshape.obj, hrestshape.obj, train_frames.npz");
  app.add_option("--holdout-every", holdout, "frames f with f % n == 0 are held out (default 4)");
  app.add_option("--train-frames", train_frames, "use only the first that many training frames (default all)");
  app.add_option("--test-frames", test_frames, "evaluate only the first that many held-out frames (default all)");
  app.add_option("--epochs", epochs, "network training epochs (default 14)");
  app.add_option("--vae-epochs", vae_epochs, "β-VAE training epochs (default 4)");
  CLI11_PARSE(app, argc, argv);
  return cli::run_guarded(
      [&] {
        Data d;
        d.problem.lr = data::read_lr_rest(dir + "/lrestshape.obj");
        d.problem.hr = data::read_hr_rest(dir + "/hrestshape.obj");
        const auto frames = data::read_paired_frames(dir + "/train_frames.npz", d.problem.num_lr(), d.problem.num_hr());
        auto split = data::holdout_every(frames.num_frames(), holdout);
        if (train_frames >= 0 && Index(split.train.size()) > train_frames) split.train.resize(std::size_t(train_frames));
        if (test_frames >= 0 && Index(split.test.size()) > test_frames) split.test.resize(std::size_t(test_frames));
        d.train = frames.select(split.train);
        d.test = frames.select(split.test);

        // Each method is one type; the code that fits, trains and evaluates it is the same.
        interp::Embedded<> embedded;
        run("embedded", embedded, d);
        interp::IDW<> idw;
        run("idw", idw, d);
        interp::MLS<> mls;
        run("mls", mls, d);
        interp::RBF<> rbf;
        run("rbf", rbf, d);
        interp::Ridge<> ridge;
        run("ridge", ridge, d);
        interp::LocalLinear<> local_linear;
        run("local_linear", local_linear, d);
        interp::BetaVaeBaseline<> vae;
        run("beta_vae", vae, d, interp::BetaVaeTrainOptions{.epochs = vae_epochs, .on_epoch = {}});
        // The official network composed with Embedded (residual), trained with the tool's defaults
        // for 2 CPU cores (README, "Training on the bunny").
        nn::NetworkConfig config = nn::NetworkConfig::official();
        config.residual = true;
        interp::Learned<> network(config);
        interp::NetworkTrainOptions net;
        net.trainer.epochs = epochs;
        net.trainer.batch_size = 8;
        net.trainer.lr = 1e-3;
        net.trainer.lr_decay_epochs = 10;
        net.trainer.progress = false;
        run("network", network, d, net);
        return 0;
      },
      "compare_methods");
}
