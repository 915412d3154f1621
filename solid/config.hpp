// Settings of the solid solver read from the scene's [solid] table (read_config): the Model
// (bodies, meshes, materials, constraints, loads, contact, planes, solver settings) plus what
// the program does around it (probes, eigenmodes, initial modal velocity). Every table is read
// strictly; solid/README.md documents every key with an example scene.
#pragma once

#include <string>
#include <vector>

#include "model.hpp"

namespace fsi {
class SceneTable;
}

namespace solid {

// A probe point counts as inside its body when it lies within this barycentric tolerance outside
// an element: a point given on the boundary (to the digits of a scene file) is accepted.
constexpr double kProbeLocateTolerance = 1e-6;

// A material point followed over time: its body and reference position.
struct ProbeSpec {
  std::string name;
  int body = 0;
  Vec2 point{0, 0};
};

struct Config {
  Model model;
  std::vector<ProbeSpec> probes;
  std::vector<MeshQuality> quality;  // per body, from the mesh checks
  int modes = 0;                     // eigenmodes to compute and write at the start
  int initial_mode = 0;              // start with the velocity of this mode (1-based, 0: none)
  double initial_mode_speed = 0;     // largest nodal speed of that initial velocity
};

// Reads [solid]. `fluid_density` is rho_f when a fluid fills the domain (the solid's inertia
// and weight then use rho_s - rho_f), 0 for a solid alone. Throws fsi::InputError naming the
// key, the value and the file.
Config read_config(const fsi::SceneTable& solid, double fluid_density = 0);

}  // namespace solid
