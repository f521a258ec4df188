// libFuzzer harness for paired-frame files (data::read_paired_frames: lowres F×N×3, highres F×M×3,
// optional frame ids, controls, sequences). Any bytes must give frames that satisfy the reader's
// promises or a simsr::Error; anything else is a finding. Inputs may be unzipped listings
// (npz_input.hpp) so mutations reach the arrays behind the zip's CRC. Seeds:
// tests/fuzz/corpus/paired_frames/ (make_corpus.cpp).
#include <simsr/data/paired_frames.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <unordered_set>

#include "npz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace simsr;
  const auto file = simsr_fuzz::write_input("paired_frames", data, size);
  if (file.empty()) return 0;
  const bool must_load = simsr_fuzz::replaying_valid_seed();
  try {
    const data::PairedFrames<> p = data::read_paired_frames(file);
    const Index F = p.num_frames();
    if (p.highres.rows() != F || Index(p.ids.size()) != F || p.lowres.cols() != 3 * p.num_lr() || p.highres.cols() != 3 * p.num_hr()) __builtin_trap();
    if (p.controls.rows() != F && p.controls.cols() != 0) __builtin_trap();
    if (!p.sequence.empty() && Index(p.sequence.size()) != F) __builtin_trap();
    for (Index i = 0; i < p.lowres.size(); ++i)
      if (!std::isfinite(p.lowres.data()[i])) __builtin_trap();
    for (Index i = 0; i < p.highres.size(); ++i)
      if (!std::isfinite(p.highres.data()[i])) __builtin_trap();
    std::unordered_set<std::int64_t> ids(p.ids.begin(), p.ids.end());
    if (Index(ids.size()) != F) __builtin_trap();
    for (Index f = 0; f < F; ++f) {
      (void)p.sequence_name(f);  // every sequence index names a sequence
      if (p.lr(f).rows() != p.num_lr() || p.hr(f).rows() != p.num_hr()) __builtin_trap();
    }
    // what was read converts back to the layout the writer writes: its own checks must pass
    try {
      (void)data::paired_frame_arrays(p);
    } catch (const Error&) {
      __builtin_trap();
    }
  } catch (const Error& e) {
    if (must_load) {
      std::fprintf(stderr, "%s: a valid seed does not load: %s\n", simsr_fuzz_replay_file, e.what());
      __builtin_trap();
    }
  }
  return 0;
}
