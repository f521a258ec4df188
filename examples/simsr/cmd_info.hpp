#pragma once
// `simsr info FILE`: one JSON object on stdout describing a mesh or array file.
#include <simsr/io/mesh_io.hpp>
#include <simsr/io/npy.hpp>
#include <simsr/io/npz.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/volume.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iostream>
#include <string>

namespace simsr::cli {

using Json = nlohmann::ordered_json;

/// Shape, dtype and (numeric arrays) value range of one array.
inline Json describe_array(const io::NpyArray& a) {
  Json j;
  j["shape"] = a.shape;
  j["dtype"] = a.dtype.name();
  if (a.fortran_order) j["fortran_order"] = true;
  auto range = [&j](const auto& v) {
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    j["min"] = *lo;
    j["max"] = *hi;
  };
  if (a.size() > 0) {
    if (a.dtype.kind == io::NpyKind::Float) range(a.to_vector<double>());
    if (a.dtype.kind == io::NpyKind::Int) range(a.to_vector<std::int64_t>());
    if (a.dtype.kind == io::NpyKind::UInt) range(a.to_vector<std::uint64_t>());
  }
  return j;
}

/// Counts, bounding box and (tets) volume of a mesh file.
inline Json describe_mesh(const std::filesystem::path& path) {
  const auto m = io::read_mesh(path);
  Json j;
  j["file"] = path.string();
  j["format"] = m.format_detail;
  j["vertices"] = m.V.rows();
  if (m.polygons > 0) j["polygons"] = m.polygons;
  if (m.F.rows() > 0 || m.T.rows() == 0) j["triangles"] = m.F.rows();
  if (m.T.rows() > 0) {
    j["tets"] = m.T.rows();
    for (Index t = 0; t < m.T.rows(); ++t)
      for (int k = 0; k < 4; ++k)
        if (m.T(t, k) < 0 || m.T(t, k) >= m.V.rows())
          throw MeshError("tet", t, "vertex index " + std::to_string(m.T(t, k)) + " out of range");
    const VecX<Scalar> vol = signed_volumes(exec::omp, m.V, m.T);
    j["volume"] = vol.sum();
    j["inverted_tets"] = (vol.array() < 0).count();
    j["boundary_triangles"] = boundary_faces(m.T).rows();
  }
  if (m.V.rows() > 0) {
    const Eigen::RowVector3d lo = m.V.colwise().minCoeff(), hi = m.V.colwise().maxCoeff();
    j["bbox"] = {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
  } else {
    j["bbox"] = nullptr;
  }
  return j;
}

inline int info(const std::string& file) {
  const std::filesystem::path path(file);
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  Json j;
  if (ext == ".npz") {
    j["file"] = file;
    j["format"] = "npz";
    Json arrays = Json::object();
    for (const auto& [name, a] : io::read_npz(path)) arrays[name] = describe_array(a);
    j["arrays"] = arrays;
  } else if (ext == ".npy") {
    j["file"] = file;
    j["format"] = "npy";
    j["arrays"] = {{path.stem().string(), describe_array(io::read_npy(path))}};
  } else {
    j = describe_mesh(path);
  }
  std::cout << j.dump() << '\n';
  return 0;
}

inline void add_info(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("info", "Describe a mesh (.obj .msh .node/.ele .mesh) or array (.npy .npz) file as one JSON object");
  auto file = std::make_shared<std::string>();
  cmd->add_option("FILE", *file, "mesh or array file")->required();
  cmd->callback([&action, file] { action = [file] { return info(*file); }; });
}

}  // namespace simsr::cli
