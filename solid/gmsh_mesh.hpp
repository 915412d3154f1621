// Gmsh import: a .geo file is meshed in 2D through the Gmsh API, a .msh file is read as is.
// Physical surfaces name material regions, physical curves name boundary edge sets and
// physical points name node sets. Quality is checked on load (finalize_mesh).
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "mesh.hpp"

namespace solid {

struct GmshOptions {
  double size_factor = 1;  // Mesh.MeshSizeFactor for .geo files
  int refine = 0;          // uniform refinements (each splits every triangle in four)
  // Values for the .geo file's DefineConstant[] parameters (as gmsh -setnumber name value).
  std::vector<std::pair<std::string, double>> parameters;
};

// Throws fsi::InputError when the file is missing, is not a Gmsh .geo/.msh file, or holds no
// triangles, or when finalize_mesh rejects an element. `key` names the scene key for messages.
Mesh read_gmsh(const std::filesystem::path& file, const GmshOptions& options = {},
               const std::string& key = "mesh");

}  // namespace solid
