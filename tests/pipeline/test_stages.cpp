// pipeline::Stages: a finished stage is reused while its fingerprint holds, rerun when it changes,
// and a stage that failed (a killed run) leaves no marker, so it runs again.
#include <simsr/pipeline/stages.hpp>

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

using namespace simsr;

namespace pipeline_stages {

std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "pipeline_stages" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

TEST_CASE("pipeline::Stages reuses a finished stage, reruns a changed one, and logs which") {
  const auto dir = fresh_dir("reuse");
  std::vector<std::string> lines;
  pipeline::Stages stages(dir, [&](const std::string& l) { lines.push_back(l); });
  int calls = 0;
  auto work = [&](int value) {
    return [&calls, value] {
      ++calls;
      return nlohmann::json{{"value", value}};
    };
  };
  const auto fp1 = pipeline::fingerprint_of({{"k", 20}}), fp2 = pipeline::fingerprint_of({{"k", 10}});
  CHECK(fp1 != fp2);
  CHECK(fp1 == pipeline::fingerprint_of({{"k", 20}}));
  CHECK(stages.run("a", fp1, work(1))["value"] == 1);
  CHECK(calls == 1);
  CHECK(stages.finished("a", fp1));
  CHECK_FALSE(stages.finished("a", fp2));
  CHECK_FALSE(stages.finished("b", fp1));
  // Same fingerprint: the stored result, work not called (even when it would now give another).
  CHECK(stages.run("a", fp1, work(2))["value"] == 1);
  CHECK(calls == 1);
  CHECK(lines.back().find("reused") != std::string::npos);
  // A new Stages object on the same folder (the next run) sees the marker too.
  pipeline::Stages again(dir);
  CHECK(again.run("a", fp1, work(3))["value"] == 1);
  CHECK(calls == 1);
  // Changed options: run again, and the new result is what is kept.
  CHECK(stages.run("a", fp2, work(4))["value"] == 4);
  CHECK(calls == 2);
  CHECK(lines.back().find("done") != std::string::npos);
  CHECK(std::find_if(lines.begin(), lines.end(), [](const std::string& l) { return l.find("changed") != std::string::npos; }) != lines.end());
  CHECK(stages.run("a", fp2, work(5))["value"] == 4);
  CHECK(calls == 2);
}

TEST_CASE("pipeline::Stages: a stage that throws leaves no marker and runs again next time") {
  const auto dir = fresh_dir("killed");
  pipeline::Stages stages(dir);
  const auto fp = pipeline::fingerprint_of("x");
  CHECK_THROWS_AS(stages.run("s", fp, []() -> nlohmann::json { throw std::runtime_error("killed"); }), std::runtime_error);
  CHECK_FALSE(stages.finished("s", fp));
  CHECK_FALSE(std::filesystem::exists(dir / "stages" / "s.json"));
  int calls = 0;
  stages.run("s", fp, [&] { return nlohmann::json(++calls); });
  CHECK(calls == 1);
}

TEST_CASE("pipeline::Stages: a foreign marker and a bad stage name are errors naming them") {
  const auto dir = fresh_dir("errors");
  pipeline::Stages stages(dir);
  for (const std::string text : {"not json", "[1, 2]", "{\"fingerprint\": 3, \"result\": 1}", "{\"result\": 1}", "{\"fingerprint\": \"ab\"}"}) {
    std::ofstream(dir / "stages" / "m.json") << text;
    CAPTURE(text);
    try {
      stages.run("m", "ab", [] { return nlohmann::json(1); });
      FAIL("no error");
    } catch (const ParseError& e) {
      CHECK(std::string(e.what()).find("m.json") != std::string::npos);
    }
  }
  for (const std::string name : {"", "a/b", "a\\b"}) CHECK_THROWS_AS(stages.run(name, "ab", [] { return nlohmann::json(1); }), ArgumentError);
}

TEST_CASE("pipeline::fingerprint_of_file follows the bytes; a missing file is named") {
  const auto dir = fresh_dir("files");
  const auto f = dir / "data.bin";
  std::ofstream(f, std::ios::binary) << std::string(200000, 'a');
  const auto a = pipeline::fingerprint_of_file(f);
  CHECK(a == pipeline::fingerprint_of_file(f));
  {
    std::fstream io(f, std::ios::binary | std::ios::in | std::ios::out);
    io.seekp(150000);
    io.put('b');
  }
  CHECK(pipeline::fingerprint_of_file(f) != a);
  try {
    pipeline::fingerprint_of_file(dir / "missing.bin");
    FAIL("no error");
  } catch (const ParseError& e) {
    CHECK(std::string(e.what()).find("missing.bin") != std::string::npos);
  }
}

}  // namespace pipeline_stages
