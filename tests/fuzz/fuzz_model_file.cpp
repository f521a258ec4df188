// libFuzzer harness for the model-file loader (nn/model_file.hpp), as interp::Learned's
// from_model_file uses it: read_model_data (config, geometry, tets, faces), read_model_arrays, the
// network the config describes built on that geometry, and load_state (every tensor's shape
// checked). Any bytes must give a loaded network or a simsr::Error; a crash, a sanitizer report,
// another exception (std::bad_alloc: a small file asking for huge tensors) or a timeout is a
// finding. Inputs may be unzipped listings (npz_input.hpp) so mutations reach the config's JSON and
// the arrays behind the zip's CRC. Seeds: tests/fuzz/corpus/model_file/ (make_corpus.cpp).
#include <simsr/nn/model_file.hpp>

#include <cstddef>
#include <cstdint>

#include "npz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace simsr;
  const auto file = simsr_fuzz::write_input("model_file", data, size);
  if (file.empty()) return 0;
  const bool must_load = simsr_fuzz::replaying_valid_seed();
  try {
    const nn::ModelData d = nn::read_model_data(file);
    // what read_model_data promises about the geometry it returns
    const Index N = d.geometry.lr_rest.rows(), M = d.geometry.hr_rest.rows();
    if (d.geometry.lr_graph.rows() != N || d.geometry.up_indices.rows() != M || d.geometry.up_distances.rows() != M) __builtin_trap();
    for (Index i = 0; i < d.lr_tets.size(); ++i)
      if (d.lr_tets.data()[i] < 0 || d.lr_tets.data()[i] >= N) __builtin_trap();
    for (Index i = 0; i < d.hr_faces.size(); ++i)
      if (d.hr_faces.data()[i] < 0 || d.hr_faces.data()[i] >= M) __builtin_trap();
    const io::NpzArrays arrays = nn::read_model_arrays(file);
    nn::Rng rng(0);
    nn::SuperResolutionNet<float> net(d.config, d.geometry, rng);
    nn::load_state(net.store(), arrays);
    net.parameters_changed();
  } catch (const Error& e) {
    if (must_load) {
      std::fprintf(stderr, "%s: a valid seed does not load: %s\n", simsr_fuzz_replay_file, e.what());
      __builtin_trap();
    }
  }
  return 0;
}
