// Writes the seed corpora of fuzz_model_file and fuzz_paired_frames: small valid files written by
// the library's own writers (a tiny network's model file, paired frames with and without ids,
// controls and sequences), each also as an unzipped listing (npz_input.hpp), and broken variants:
// truncated, oversized (a tiny file whose config or header asks for huge tensors), misshapen,
// non-finite. Seeds named valid_* must load (the replay tests check it).
//
//   cmake --build build --target fuzz_make_corpus && build/tests/fuzz/fuzz_make_corpus tests/fuzz/corpus
//
// Not built by default: the committed seeds are its output; rerun it when a layout changes.
#include <simsr/data/paired_frames.hpp>
#include <simsr/nn/model_file.hpp>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "../nn/network_fixture.hpp"
#include "npz_input.hpp"

namespace {

using namespace simsr;
namespace fs = std::filesystem;

std::string bytes_of(const std::vector<std::byte>& b) { return std::string(reinterpret_cast<const char*>(b.data()), b.size()); }

void put(const fs::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + file.string());
  std::printf("%s (%zu bytes)\n", file.c_str(), bytes.size());
}

/// The arrays as an unzipped listing: member NAME.npy holds each array's .npy bytes.
std::string listing(const io::NpzArrays& arrays) {
  std::vector<std::pair<std::string, std::string>> members;
  for (const auto& [name, a] : arrays) {
    members.emplace_back(name + ".npy", bytes_of(io::npy_bytes(a)));
    if (members.back().second.find(simsr_fuzz::member_mark) != std::string::npos)
      throw std::runtime_error("array '" + name + "' contains the listing's member mark; change the seed's values");
  }
  return simsr_fuzz::listing(members);
}

/// A valid seed, as a stored .npz and as a listing, plus the .npz truncated to 60 %.
void put_valid(const fs::path& dir, const std::string& stem, const io::NpzArrays& arrays) {
  const std::string npz = bytes_of(io::npz_bytes(arrays));
  put(dir / ("valid_" + stem + ".npz"), npz);
  put(dir / ("valid_" + stem + "_listing"), listing(arrays));
  put(dir / ("truncated_" + stem + ".npz"), npz.substr(0, npz.size() * 3 / 5));
}

void put_broken(const fs::path& dir, const std::string& name, const io::NpzArrays& arrays) { put(dir / (name + "_listing"), listing(arrays)); }

nn::ModelData tiny_model_data(const nn::NetworkConfig& cfg, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  nn::ModelData md;
  md.config = cfg;
  md.geometry = test::small_network_geometry(rng, 8, 10, cfg);
  md.lr_tets = Tets(2, 4);
  md.lr_tets << 0, 1, 2, 3, 1, 2, 3, 4;
  md.hr_faces = Tris(3, 3);
  md.hr_faces << 0, 1, 2, 2, 3, 4, 5, 6, 7;
  return md;
}

io::NpzArrays model_arrays(const nn::NetworkConfig& cfg, std::uint64_t seed) {
  const nn::ModelData md = tiny_model_data(cfg, seed);
  nn::Rng rng(seed);
  nn::SuperResolutionNet<float> net(cfg, md.geometry, rng);
  return nn::model_arrays(net, md);
}

io::NpyArray config_array(const nlohmann::json& j) {
  io::NpyArray a = io::make_npy(std::vector<std::string>{j.dump()});
  a.shape.clear();
  return a;
}

void model_corpus(const fs::path& dir) {
  fs::create_directories(dir);
  nn::NetworkConfig official = test::tiny_config(nn::NetworkConfig::official());
  official.knn = 2;
  official.up_k = 3;
  nn::NetworkConfig paper = test::tiny_config(nn::NetworkConfig::paper());
  paper.knn = 2;
  paper.up_k = 3;
  nn::NetworkConfig residual = official;
  residual.residual = true;
  const io::NpzArrays a = model_arrays(official, 1);
  put_valid(dir, "official", a);
  put_valid(dir, "paper", model_arrays(paper, 2));
  put_valid(dir, "residual", model_arrays(residual, 3));

  // a config asking for tensors far beyond what the file holds (16 GB of f_θ weights)
  io::NpzArrays huge = a;
  nlohmann::json j = official.to_json();
  j["up_hidden"] = {6, 1'000'000'000};
  huge.at("config") = config_array(j);
  put_broken(dir, "oversized_config", huge);
  // the same, a wider decoder instead
  j = official.to_json();
  j["decoder_dims"] = {18, 2'000'000'000, 3};
  huge.at("config") = config_array(j);
  put_broken(dir, "oversized_decoder", huge);
  // an array header declaring 10⁹ LR vertices over a few bytes of data (same header length)
  std::string l = listing(a);
  const std::string real = bytes_of(io::npy_bytes(a.at("lr_rest")));
  const std::string header = real.substr(0, real.find('\n', real.find('}')) + 1);
  const std::size_t at = header.find("(8, 3)");
  if (at == std::string::npos) throw std::runtime_error("unexpected lr_rest header: " + header);
  std::string big = header;
  big.replace(at, 6, "(1000000000, 3)");
  while (big.size() > header.size() && big[big.size() - 2] == ' ') big.erase(big.size() - 2, 1);
  if (big.size() != header.size()) throw std::runtime_error("no room in the lr_rest header: " + header);
  l.replace(l.find(header), header.size(), big);
  put(dir / "oversized_header_listing", l);
  // a state tensor of the wrong shape, one missing, one not finite, a stray one
  io::NpzArrays wrong = a;
  for (auto& [name, arr] : wrong)
    if (nn::is_state_tensor_name(name) && arr.ndim() == 2) {
      arr.shape = {arr.shape[1], arr.shape[0]};
      if (arr.shape[0] != arr.shape[1]) break;
    }
  put_broken(dir, "transposed_weight", wrong);
  io::NpzArrays nan = a;
  for (auto& [name, arr] : nan)
    if (nn::is_state_tensor_name(name) && arr.dtype == io::NpyDType::of<float>() && arr.size() > 0) {
      const float q = std::numeric_limits<float>::quiet_NaN();
      std::memcpy(arr.bytes.data(), &q, sizeof q);
      break;
    }
  put_broken(dir, "nan_weight", nan);
  io::NpzArrays stray = a;
  stray["net_decoder.decoder.extra.weight"] = io::make_npy(Eigen::MatrixXf::Ones(2, 2).eval());
  put_broken(dir, "stray_tensor", stray);
  // geometry: an index out of range, a graph with the wrong row count, no config
  io::NpzArrays range = a;
  range.at("hr_faces") = io::make_npy(Eigen::Matrix<std::int64_t, 1, 3>(0, 1, 99).eval());
  put_broken(dir, "face_out_of_range", range);
  io::NpzArrays rows = a;
  rows.at("lr_graph") = io::make_npy(Eigen::Matrix<std::int64_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>::Zero(3, 4).eval());
  put_broken(dir, "graph_rows", rows);
  io::NpzArrays noconfig;
  for (const auto& [name, arr] : a)
    if (name != "config") noconfig[name] = arr;
  put_broken(dir, "no_config", noconfig);
}

data::PairedFrames<> frames(Index F, Index N, Index M, bool extras, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  data::PairedFrames<> p;
  p.lowres.resize(F, 3 * N);
  p.highres.resize(F, 3 * M);
  for (Index i = 0; i < p.lowres.size(); ++i) p.lowres.data()[i] = u(rng);
  for (Index i = 0; i < p.highres.size(); ++i) p.highres.data()[i] = u(rng);
  for (Index f = 0; f < F; ++f) p.ids.push_back(extras ? 10 * f + 3 : f);
  p.controls.resize(F, extras ? 2 : 0);
  for (Index i = 0; i < p.controls.size(); ++i) p.controls.data()[i] = u(rng);
  if (extras) {
    p.sequence_names = {"amazement", "pain"};
    for (Index f = 0; f < F; ++f) p.sequence.push_back(std::int32_t(f % 2));
  }
  return p;
}

void paired_corpus(const fs::path& dir) {
  fs::create_directories(dir);
  const auto minimal = frames(3, 4, 5, false, 1);
  io::NpzArrays plain;  // lowres and highres only, as the authors' older files
  plain["lowres"] = data::paired_frame_arrays(minimal).at("lowres");
  plain["highres"] = data::paired_frame_arrays(minimal).at("highres");
  put_valid(dir, "minimal", plain);
  const io::NpzArrays full = data::paired_frame_arrays(frames(4, 3, 6, true, 2));
  put_valid(dir, "full", full);
  io::NpzArrays f32 = plain;  // float32 LR positions, as PyTorch writes them
  const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> lo = minimal.lowres.cast<float>();
  f32.at("lowres") = io::make_npy<float>(f32.at("lowres").shape, lo.data());
  put_valid(dir, "float32", f32);

  io::NpzArrays nan = full;
  const double q = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(nan.at("highres").bytes.data() + 5 * sizeof(double), &q, sizeof q);
  put_broken(dir, "nan_highres", nan);
  io::NpzArrays dup = full;
  const std::int64_t ids[] = {3, 13, 3, 33};
  dup.at("frame") = io::make_npy<std::int64_t>({4}, ids);
  put_broken(dir, "duplicate_ids", dup);
  io::NpzArrays fewer = full;
  fewer.at("highres").shape[0] = 3;
  fewer.at("highres").bytes.resize(fewer.at("highres").bytes.size() * 3 / 4);
  put_broken(dir, "frame_count_mismatch", fewer);
  io::NpzArrays seq = full;
  const std::int32_t s[] = {0, 1, 2, 1};
  seq.at("sequence") = io::make_npy<std::int32_t>({4}, s);
  put_broken(dir, "sequence_out_of_range", seq);
  io::NpzArrays nonames;
  for (const auto& [name, arr] : full)
    if (name != "sequence_names") nonames[name] = arr;
  put_broken(dir, "sequence_without_names", nonames);
  io::NpzArrays flat = full;
  flat.at("lowres").shape = {4, 9};
  put_broken(dir, "lowres_2d", flat);
  io::NpzArrays many = plain;  // more frames than max_frames, declared in a 2-vertex array
  many.at("lowres") = io::make_npy<double>({2'000'000, 0, 3}, static_cast<const double*>(nullptr));
  put_broken(dir, "too_many_frames", many);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CORPUS_DIR (tests/fuzz/corpus)\n", argv[0]);
    return 2;
  }
  try {
    model_corpus(fs::path(argv[1]) / "model_file");
    paired_corpus(fs::path(argv[1]) / "paired_frames");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_make_corpus: %s\n", e.what());
    return 1;
  }
  return 0;
}
