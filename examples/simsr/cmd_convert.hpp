#pragma once
// `simsr convert IN OUT`: between mesh formats, chosen by extension.
#include <simsr/io/mesh_io.hpp>

#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>
#include <string>

namespace simsr::cli {

struct ConvertArgs {
  std::string in, out, keep, msh_version = "4.1";
  bool ascii = false;
};

inline int convert(const ConvertArgs& a) {
  auto m = io::read_mesh(a.in);
  if (!a.keep.empty()) m.keep(a.keep);
  io::MeshWriteOptions opt;
  if (a.msh_version == "2.2")
    opt.msh_version = io::MshVersion::v22;
  else if (a.msh_version != "4.1")
    throw ArgumentError("--msh-version: expected 2.2 or 4.1, got '" + a.msh_version + "'");
  if (a.ascii) opt.vtu_format = io::VtuFormat::Ascii;
  io::write_mesh(a.out, m, opt);
  std::cerr << "simsr: wrote " << a.out << " (" << m.V.rows() << " vertices, " << m.T.rows() << " tets, " << m.F.rows()
            << " triangles)\n";
  return 0;
}

inline void add_convert(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("convert", "Convert a mesh between .obj .msh .node/.ele .mesh (and to .vtu), by extension");
  auto args = std::make_shared<ConvertArgs>();
  cmd->add_option("IN", args->in, "input mesh")->required();
  cmd->add_option("OUT", args->out, "output mesh")->required();
  cmd->add_option("--keep", args->keep, "keep only 'tets' or 'triangles' (OBJ holds one kind)");
  cmd->add_option("--msh-version", args->msh_version, "Gmsh format version for .msh output: 4.1 (default) or 2.2");
  cmd->add_flag("--ascii", args->ascii, "write .vtu as ASCII instead of binary");
  cmd->callback([&action, args] { action = [args] { return convert(*args); }; });
}

}  // namespace simsr::cli
