#pragma once
// `--substeps`, `--stepping inexact|converged` and `--step-iterations` (datagen's sheet and disk,
// demo's sheet and disk): how the cloth's backward-Euler steps are taken (shell::ClothStepping),
// one set of options for both commands.
#include <simsr/core/types.hpp>
#include <simsr/shell/cloth_simulator.hpp>

#include <CLI/CLI.hpp>

#include <string>

namespace simsr::cli {

struct ClothSteppingArgs {
  Index substeps = shell::ClothOptions{}.substeps;
  std::string stepping = "inexact";
  Index step_iterations = 0;  ///< 0: the stepping's default budget or cap

  /// Sets o's substeps and Newton options from the parsed values.
  void apply(shell::ClothOptions& o) const {
    o.substeps = substeps;
    o.newton = shell::cloth_newton_options(shell::parse_cloth_stepping(stepping), step_iterations);
  }
};

/// Adds the three options to `cmd`; `scope` starts each description ("sheet, disk").
inline void add_cloth_stepping_options(CLI::App* cmd, ClothSteppingArgs& a, const std::string& scope) {
  cmd->add_option("--substeps", a.substeps, scope + ": backward-Euler steps per frame (the same for both resolutions)")
      ->capture_default_str()
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--stepping", a.stepping,
                  scope + ": each backward-Euler step inexact (at most --step-iterations projected Newton iterations, 3 by default; 1 is "
                          "ARCSim's linearized step) or converged (Newton to 1e-6, at most 30 iterations)")
      ->capture_default_str()
      ->check(CLI::IsMember({"inexact", "converged"}));
  cmd->add_option("--step-iterations", a.step_iterations,
                  scope + ": Newton iterations per step, the inexact steps' budget or the converged steps' cap (0: 3 / 30)")
      ->capture_default_str()
      ->check(CLI::Range(0, 10000));
}

}  // namespace simsr::cli
