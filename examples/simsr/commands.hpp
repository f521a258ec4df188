#pragma once
// Subcommands in source files of their own (the heavy ones). The tool builds as one unity
// translation unit (examples/CMakeLists.txt): its commands instantiate the same library templates
// (the face simulation, the network's training and inference, every interpolator), which one
// translation unit compiles once.
#include <CLI/CLI.hpp>

#include <functional>

namespace simsr::cli {
void add_demo(CLI::App& app, std::function<int()>& action);
void add_ablate(CLI::App& app, std::function<int()>& action);
void add_animate(CLI::App& app, std::function<int()>& action);
}  // namespace simsr::cli
