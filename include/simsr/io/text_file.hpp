#pragma once
/// \file
/// A whole file read into a string (JSON summaries, region lists), with a ParseError naming the
/// file when it cannot be opened; `hint` (optional) is appended to say what the file should be.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "../core/error.hpp"

namespace simsr::io {

inline std::string read_text_file(const std::filesystem::path& p, const std::string& hint = "") {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw ParseError(p.string(), 0, hint.empty() ? "cannot open" : "cannot open (" + hint + ")");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace simsr::io
