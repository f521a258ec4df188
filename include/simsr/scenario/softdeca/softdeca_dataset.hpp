#pragma once
/// \file
/// SoftDECA's sampled data as the surrogate reads it: `DIR/softdeca_samples.npz`, written by
/// generate_softdeca_dataset (softdeca_datagen.hpp), read back with its shapes checked. Its own
/// header so that a reader (nn/softdeca_surrogate.hpp) needs neither the simulator nor the template.
///
///     auto data = scenario::read_softdeca_dataset("out/softdeca");   // the directory or the .npz

#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "../../core/error.hpp"
#include "../../core/types.hpp"
#include "../../io/npz.hpp"
#include "parameters.hpp"

namespace simsr::scenario {

/// softdeca_samples.npz read back.
struct SoftDecaDataset {
  Eigen::MatrixXd parameters;   ///< N × 20 (SoftDecaParameters::to_vector)
  std::vector<std::string> parameter_names;
  Eigen::MatrixXd expressions;  ///< N × E weights
  std::vector<std::string> expression_names;
  Eigen::MatrixXd displacements;  ///< N × 3·#skin: skin at the last step − the template's rest skin (m), vertex-major
  Points<> rest_skin;             ///< #skin × 3 (m)
  VecX<> seconds;                 ///< N: each sample's simulation time (s)
  std::string fingerprint;
  Index size() const { return parameters.rows(); }
  Index skin_vertices() const { return rest_skin.rows(); }
};

/// Reads DIR/softdeca_samples.npz (or the .npz given). Error naming the file and the array for a
/// missing array or inconsistent shapes.
inline SoftDecaDataset read_softdeca_dataset(const std::filesystem::path& path) {
  const std::filesystem::path file = std::filesystem::is_directory(path) ? path / "softdeca_samples.npz" : path;
  const io::NpzArrays z = io::read_npz(file);
  const auto need = [&](const char* name) -> const io::NpyArray& {
    if (!z.contains(name)) throw Error("softdeca dataset " + file.string() + ": no array '" + name + "' (not a simsr datagen --scenario softdeca output?)");
    return z.at(name);
  };
  SoftDecaDataset d;
  d.parameters = need("parameters").to_matrix<double>();
  d.parameter_names = need("parameter_names").to_strings();
  d.expressions = need("expressions").to_matrix<double>();
  d.expression_names = need("expression_names").to_strings();
  d.rest_skin = need("rest_skin").to_points();
  d.seconds = need("seconds").to_matrix<double>().reshaped();
  d.fingerprint = need("fingerprint").to_strings().at(0);
  const io::NpyArray& skin = need("skin");
  const Index N = d.parameters.rows(), M = d.rest_skin.rows();
  const auto bad = [&](const std::string& what) { throw Error("softdeca dataset " + file.string() + ": " + what); };
  if (d.parameters.cols() != SoftDecaParameters::size || Index(d.parameter_names.size()) != SoftDecaParameters::size)
    bad("parameters must be N x " + std::to_string(SoftDecaParameters::size));
  if (d.expressions.rows() != N || d.expressions.cols() != Index(d.expression_names.size())) bad("expressions must be N x E (E names)");
  if (d.seconds.size() != N) bad("seconds must have N entries");
  if (skin.ndim() != 3 || skin.num_frames() != N || skin.shape[1] != M || skin.shape[2] != 3) bad("skin must be N x #skin x 3");
  if (!d.parameters.allFinite() || !d.expressions.allFinite()) bad("non-finite parameters or expressions");
  d.displacements.resize(N, 3 * M);
  for (Index i = 0; i < N; ++i) {
    const Points<> s = skin.frame_points(i);
    if (!s.allFinite()) bad("sample " + std::to_string(i) + "'s skin is not finite");
    d.displacements.row(i) = Eigen::Map<const VecX<>>(Points<>(s - d.rest_skin).data(), 3 * M).transpose();
  }
  return d;
}

}  // namespace simsr::scenario
