#pragma once
// `simsr train-surrogate --data DIR --out OUT [--epochs N] [--hidden 256,256,256] [--batch B]
//  [--lr LR] [--held-out F] [--validation F] [--weight-decay W] [--linear-base] [--seed S]`: SoftDECA's surrogate
// (nn/softdeca_surrogate.hpp, nn::train_softdeca_surrogate_files) trained on a
// `simsr datagen --scenario softdeca` output. Writes OUT/surrogate.npz (the model),
// OUT/surrogate_report.json (held-out error beside the mean and ridge baselines, inference and
// solver seconds per sample) and OUT/surrogate_loss.csv (loss per epoch), prints the report.
#include <simsr/nn/softdeca_surrogate.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace simsr::cli {

struct SurrogateArgs {
  std::string data, out;
  std::vector<Index> hidden = {256, 256, 256};
  nn::SoftDecaSurrogateOptions options;
};

inline int train_surrogate(const SurrogateArgs& a) {
  const auto j = nn::train_softdeca_surrogate_files(exec::omp, a.data, a.out, a.hidden, a.options,
                                                    [](const std::string& line) { std::fprintf(stderr, "train-surrogate: %s\n", line.c_str()); });
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
  cmd->add_flag("--linear-base", a->options.linear_base,
               "add a ridge map of the 20 parameters fitted on the training samples (lambda picked on the validation ones); the network learns what it leaves");
  cmd->add_option("--seed", a->options.seed, "initialization and batch-order seed")->capture_default_str();
  cmd->callback([a, &action] { action = [a] { return train_surrogate(*a); }; });
}

}  // namespace simsr::cli
