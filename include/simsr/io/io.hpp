#pragma once
/// \file
/// Umbrella of the io area: every reader and writer, read_mesh/write_mesh by extension, and the
/// atomic file writing every writer goes through.
#include "atomic_file.hpp"
#include "medit.hpp"
#include "mesh_io.hpp"
#include "msh.hpp"
#include "npy.hpp"
#include "npz.hpp"
#include "obj.hpp"
#include "tetgen.hpp"
#include "vtu.hpp"
