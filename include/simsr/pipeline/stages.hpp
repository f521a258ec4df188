#pragma once
/// \file
/// Long pipelines as stages that a rerun reuses: each finished stage leaves a marker
/// DIR/stages/<name>.json holding the fingerprint of everything it was computed from (its options
/// and its inputs' fingerprints) and its result; the next run skips a stage whose marker holds the
/// same fingerprint and returns the stored result. A stage whose options or inputs changed runs
/// again (and, since the stages after it include its fingerprint in theirs, so do they). The
/// marker is written atomically after the stage's own outputs, so a run killed inside a stage
/// redoes that stage only (and the stage itself may resume from its own checkpoint).
///
///     pipeline::Stages stages("out/demo", [](const std::string& line) { std::cerr << line << '\n'; });
///     auto fp = pipeline::fingerprint_of({{"k", 20}, {"data", data_fp}});
///     nlohmann::json r = stages.run("neighbors", fp, [&] { /* compute, write files */ return nlohmann::json{{"seconds", s}}; });

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "../core/error.hpp"
#include "../core/fingerprint.hpp"
#include "../io/atomic_file.hpp"

namespace simsr::pipeline {

/// Where a pipeline's progress lines go (stderr in the tool; nothing when empty).
using Log = std::function<void(const std::string&)>;

/// The fingerprint of a JSON value (its compact dump): options and upstream fingerprints.
inline std::string fingerprint_of(const nlohmann::json& what) {
  const std::string text = what.dump();
  return Fingerprint().add_bytes(text.data(), text.size()).hex();
}

/// The fingerprint of a file's bytes (an input the pipeline did not write, e.g. a dataset).
/// ParseError when it cannot be read.
inline std::string fingerprint_of_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ParseError(file.string(), 0, "cannot open the file to fingerprint it");
  Fingerprint f;
  char buf[1 << 16];
  while (in) {
    in.read(buf, sizeof buf);
    f.add_bytes(buf, std::size_t(in.gcount()));
  }
  if (in.bad()) throw ParseError(file.string(), 0, "read failed while fingerprinting it");
  return f.hex();
}

class Stages {
 public:
  explicit Stages(std::filesystem::path dir, Log log = {}) : dir_(std::move(dir)), log_(std::move(log)) {
    std::filesystem::create_directories(dir_ / "stages");
  }

  const std::filesystem::path& dir() const { return dir_; }
  void say(const std::string& line) const {
    if (log_) log_(line);
  }

  /// The result of stage `name`: stored when its marker holds `fingerprint`, otherwise `work()`'s
  /// (which must have written the stage's files before returning), then recorded. A marker that is
  /// not a marker of this kind is a ParseError naming the file (never silently overwritten).
  template <class Work>
  nlohmann::json run(const std::string& name, const std::string& fingerprint, Work&& work) {
    const auto marker = marker_path(name);
    if (std::filesystem::exists(marker)) {
      const nlohmann::json m = read_marker(marker);
      if (m.at("fingerprint").get<std::string>() == fingerprint) {
        say("stage " + name + ": reused (finished earlier, same inputs; delete " + marker.string() + " to redo it)");
        return m.at("result");
      }
      say("stage " + name + ": its options or inputs changed since it last ran: running it again");
    } else {
      say("stage " + name + ": running");
    }
    const auto t0 = std::chrono::steady_clock::now();
    nlohmann::json result = work();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    nlohmann::json m{{"stage", name}, {"fingerprint", fingerprint}, {"seconds", seconds}, {"result", result}};
    io::write_file_atomic(marker, m.dump(2) + "\n");
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.1f s", seconds);
    say("stage " + name + ": done in " + buf);
    return result;
  }

  /// Whether stage `name` finished with `fingerprint` (its result would be reused).
  bool finished(const std::string& name, const std::string& fingerprint) const {
    const auto marker = marker_path(name);
    return std::filesystem::exists(marker) && read_marker(marker).at("fingerprint").get<std::string>() == fingerprint;
  }

 private:
  std::filesystem::path marker_path(const std::string& name) const {
    if (name.empty() || name.find_first_of("/\\") != std::string::npos) throw ArgumentError("pipeline::Stages: bad stage name '" + name + "'");
    return dir_ / "stages" / (name + ".json");
  }
  static nlohmann::json read_marker(const std::filesystem::path& marker) {
    std::ifstream in(marker);
    std::stringstream text;
    text << in.rdbuf();
    nlohmann::json m = nlohmann::json::parse(text.str(), nullptr, false);
    if (m.is_discarded() || !m.is_object() || !m.contains("fingerprint") || !m["fingerprint"].is_string() || !m.contains("result"))
      throw ParseError(marker.string(), 0, "not a stage marker (a JSON object with 'fingerprint' and 'result'); delete it to rerun the stage");
    return m;
  }

  std::filesystem::path dir_;
  Log log_;
};

}  // namespace simsr::pipeline
