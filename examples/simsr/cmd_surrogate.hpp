#pragma once
// `simsr train-surrogate --data DIR --out OUT [--epochs N] [--hidden 256,256,256] [--batch B]
//  [--lr LR] [--held-out F] [--validation F] [--weight-decay W] [--seed S]`: SoftDECA's surrogate (scenario/softdeca/surrogate.hpp)
// trained on a `simsr datagen --scenario softdeca` output. Writes OUT/surrogate.npz (the model),
// OUT/surrogate_report.json (held-out error beside the mean and ridge baselines, inference and
// solver seconds per sample) and OUT/surrogate_loss.csv (loss per epoch), prints the report.
#include <simsr/io/atomic_file.hpp>
#include <simsr/scenario/softdeca/surrogate.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace simsr::cli {

struct SurrogateArgs {
  std::string data, out;
  std::vector<Index> hidden = {256, 256, 256};
  scenario::SoftDecaSurrogateOptions options;
};

inline int train_surrogate(const SurrogateArgs& a) {
  namespace fs = std::filesystem;
  const scenario::SoftDecaDataset data = scenario::read_softdeca_dataset(a.data);
  std::fprintf(stderr, "train-surrogate: %lld samples, %lld skin vertices, %lld expressions\n", static_cast<long long>(data.size()),
               static_cast<long long>(data.skin_vertices()), static_cast<long long>(data.expressions.cols()));
  scenario::SoftDecaSurrogate net(data.expressions.cols(), data.skin_vertices(), a.hidden, a.options.seed);
  scenario::SoftDecaSurrogateOptions o = a.options;
  o.progress = [&](Index epoch, double loss) {
    if (epoch == 0 || (epoch + 1) % 25 == 0 || epoch + 1 == o.epochs)
      std::fprintf(stderr, "train-surrogate: epoch %lld/%lld loss %.5f\n", static_cast<long long>(epoch + 1), static_cast<long long>(o.epochs), loss);
  };
  const scenario::SoftDecaSurrogateReport r = scenario::train_softdeca_surrogate(exec::omp, data, o, net);
  fs::create_directories(a.out);
  nlohmann::ordered_json meta = {{"data", a.data}, {"data_fingerprint", data.fingerprint}};
  net.save(fs::path(a.out) / "surrogate.npz", meta);
  nlohmann::ordered_json j = r.to_json();
  j["data"] = a.data;
  j["hidden"] = a.hidden;
  j["batch"] = o.batch;
  j["lr"] = o.lr;
  j["weight_decay"] = o.weight_decay;
  j["seed"] = o.seed;
  io::write_file_atomic(fs::path(a.out) / "surrogate_report.json", j.dump(2) + "\n");
  std::ostringstream csv;
  csv << "epoch,train_loss\n";
  for (std::size_t e = 0; e < r.loss.size(); ++e) csv << e + 1 << ',' << r.loss[e] << '\n';
  io::write_file_atomic(fs::path(a.out) / "surrogate_loss.csv", csv.str());
  std::cout << j.dump() << '\n';
  return 0;
}

inline void add_train_surrogate(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("train-surrogate", "Train SoftDECA's surrogate network on `simsr datagen --scenario softdeca` samples");
  auto a = std::make_shared<SurrogateArgs>();
  cmd->add_option("--data", a->data, "the datagen output directory (softdeca_samples.npz) or the .npz itself")->required();
  cmd->add_option("--out", a->out, "output directory (surrogate.npz, surrogate_report.json, surrogate_loss.csv)")->required();
  cmd->add_option("--hidden", a->hidden, "hidden layer widths, comma-separated")->delimiter(',')->capture_default_str();
  cmd->add_option("--epochs", a->options.epochs, "training epochs")->capture_default_str()->check(CLI::Range(1, 1000000));
  cmd->add_option("--batch", a->options.batch, "samples per mini-batch")->capture_default_str()->check(CLI::Range(1, 1000000));
  cmd->add_option("--lr", a->options.lr, "Adam's learning rate (cosine-decayed to 1 %)")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--held-out", a->options.held_out, "fraction of the samples (the last ones) held out for the report")
      ->capture_default_str()->check(CLI::Range(0.001, 0.999));
  cmd->add_option("--validation", a->options.validation, "fraction of the training samples (their last ones) that picks the epoch kept (0: the last)")
      ->capture_default_str()->check(CLI::Range(0.0, 0.999));
  cmd->add_option("--weight-decay", a->options.weight_decay, "Adam's L2 weight decay")->capture_default_str()->check(CLI::NonNegativeNumber);
  cmd->add_option("--seed", a->options.seed, "initialization and batch-order seed")->capture_default_str();
  cmd->callback([a, &action] { action = [a] { return train_surrogate(*a); }; });
}

}  // namespace simsr::cli
