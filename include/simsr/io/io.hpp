#pragma once
/// \file
/// Umbrella of the io area: every reader and writer, and read_mesh/write_mesh by extension.
#include "medit.hpp"
#include "mesh_io.hpp"
#include "msh.hpp"
#include "npy.hpp"
#include "npz.hpp"
#include "obj.hpp"
#include "tetgen.hpp"
#include "vtu.hpp"
