#pragma once
// The input of the harnesses that read an .npz from a path (fuzz_model_file, fuzz_paired_frames).
// A mutated zip mostly dies at its CRC or in inflate, so an input may also be an unzipped listing:
//
//   "SIMSRZIP" ( "\n@@" NAME "\n" BYTES )*
//
// Each member's BYTES (an .npy, usually) are zipped here, stored, under NAME, so mutations of a
// config's JSON text, an .npy header or an array's values reach the loader itself. Any other input
// is written as it is. write_input() puts the bytes in a per-process file and returns its path.
#include <zip.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace simsr_fuzz {

inline constexpr std::string_view zip_tag = "SIMSRZIP";
inline constexpr std::string_view member_mark = "\n@@";

/// (name, bytes) of an unzipped listing (the input without its tag).
inline std::vector<std::pair<std::string, std::string_view>> split_members(std::string_view s) {
  std::vector<std::pair<std::string, std::string_view>> out;
  std::size_t at = s.find(member_mark);
  while (at != std::string_view::npos) {
    const std::size_t name_start = at + member_mark.size();
    const std::size_t name_end = s.find('\n', name_start);
    if (name_end == std::string_view::npos) break;
    const std::size_t next = s.find(member_mark, name_end + 1);
    const std::size_t end = next == std::string_view::npos ? s.size() : next;
    out.emplace_back(std::string(s.substr(name_start, name_end - name_start)), s.substr(name_end + 1, end - name_end - 1));
    at = next;
  }
  return out;
}

/// A stored zip of `members` (empty when libzip refuses, e.g. a duplicate or empty name).
inline std::vector<std::byte> zip_members(const std::vector<std::pair<std::string, std::string_view>>& members) {
  zip_error_t err;
  zip_error_init(&err);
  zip_source_t* out = zip_source_buffer_create(nullptr, 0, 0, &err);
  zip_error_fini(&err);
  if (!out) return {};
  zip_source_keep(out);
  std::vector<std::byte> bytes;
  bool ok = true;
  if (zip_t* z = zip_open_from_source(out, ZIP_TRUNCATE, nullptr)) {
    for (const auto& [name, data] : members) {
      zip_source_t* m = zip_source_buffer(z, data.data(), data.size(), 0);
      const zip_int64_t idx = m ? zip_file_add(z, name.c_str(), m, 0) : -1;
      if (idx < 0) {
        if (m) zip_source_free(m);
        ok = false;
        break;
      }
      zip_set_file_compression(z, static_cast<zip_uint64_t>(idx), ZIP_CM_STORE, 0);
    }
    if (!ok || zip_close(z) != 0) {
      zip_discard(z);
      ok = false;
    }
  } else {
    ok = false;
  }
  if (ok && zip_source_open(out) == 0) {
    zip_stat_t st;
    zip_stat_init(&st);
    if (zip_source_stat(out, &st) == 0 && (st.valid & ZIP_STAT_SIZE)) {
      bytes.resize(st.size);
      if (zip_source_read(out, bytes.data(), st.size) != static_cast<zip_int64_t>(st.size)) bytes.clear();
    }
    zip_source_close(out);
  }
  zip_source_free(out);
  return bytes;
}

/// The listing `members` as one input (what the corpus generator writes).
inline std::string listing(const std::vector<std::pair<std::string, std::string>>& members) {
  std::string s(zip_tag);
  for (const auto& [name, data] : members) s += std::string(member_mark) + name + "\n" + data;
  return s;
}

/// Writes the input (zipped first when it is a listing) to this process's file for `harness` and
/// returns its path; an empty path when a listing cannot be zipped (nothing to test).
inline std::filesystem::path write_input(const char* harness, const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("simsr_fuzz_" + std::string(harness) + "_" + std::to_string(::getpid()) + ".npz");
  static const struct Remove {
    const std::filesystem::path& f;
    ~Remove() {
      std::error_code ec;
      std::filesystem::remove(f, ec);
    }
  } remove_at_exit{file};
  std::vector<std::byte> zipped;
  const std::string_view in(reinterpret_cast<const char*>(data), size);
  if (in.substr(0, zip_tag.size()) == zip_tag) {
    zipped = zip_members(split_members(in.substr(zip_tag.size())));
    if (zipped.empty()) return {};
    data = reinterpret_cast<const std::uint8_t*>(zipped.data());
    size = zipped.size();
  }
  std::FILE* f = std::fopen(file.c_str(), "wb");
  if (!f) __builtin_trap();  // the harness's own temporary file: nothing to fuzz without it
  if (size && std::fwrite(data, 1, size, f) != size) __builtin_trap();
  std::fclose(f);
  return file;
}

}  // namespace simsr_fuzz

// Set by replay_main.cpp to the corpus file being replayed (absent under libFuzzer): the harnesses
// require that seeds named valid_* load, so a corpus the loader no longer accepts cannot pass by
// exercising only the error paths.
extern "C" const char* simsr_fuzz_replay_file __attribute__((weak));

namespace simsr_fuzz {
inline bool replaying_valid_seed() {
  if (&simsr_fuzz_replay_file == nullptr || simsr_fuzz_replay_file == nullptr) return false;
  return std::filesystem::path(simsr_fuzz_replay_file).filename().string().rfind("valid_", 0) == 0;
}
}  // namespace simsr_fuzz
