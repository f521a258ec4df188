#pragma once
// `--fine-cells` and `--fine-frames-from` (datagen's sheet and disk, demo's sheet and disk): a
// fine cloth of its own beside the coarse one, and its frames taken from another dataset (the
// supplement's scale study: one fine simulation, coarse inputs of three sizes; README "Thin
// shells"), one set of options for both commands.
#include <simsr/core/types.hpp>

#include <CLI/CLI.hpp>

#include <string>

namespace simsr::cli {

inline void add_fine_cloth_options(CLI::App* cmd, Index& fine_cells, std::string& fine_frames_from) {
  cmd->add_option("--fine-cells", fine_cells,
                  "sheet: the fine cloth is a sheet of this many cells per side Loop-subdivided --levels times, beside the --cells coarse "
                  "one (default: --cells; the scale study: --cells 16 / 8 / 4 with --fine-cells 8)")
      ->check(CLI::Range(2, 1000));
  cmd->add_option("--fine-frames-from", fine_frames_from,
                  "sheet/disk: a dataset folder (datagen's --out, demo's OUT/data) of the same fine cloth, seed and options whose fine "
                  "frames this run takes instead of simulating them again (refused, naming the file, when they are another simulation's)");
}

}  // namespace simsr::cli
