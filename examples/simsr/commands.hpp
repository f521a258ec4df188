#pragma once
// Subcommands compiled in their own translation units (the heavy ones: two cores build them in
// parallel, and a change to one does not rebuild the others).
#include <CLI/CLI.hpp>

#include <functional>

namespace simsr::cli {
void add_demo(CLI::App& app, std::function<int()>& action);
}  // namespace simsr::cli
