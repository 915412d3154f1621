// fsi-plan SCENE.toml: what the launcher needs to compose the mpirun line, read with the same
// strict rules as the programs. Prints "roles: fluid solid coupler", "programs: fluid solid-rigid
// coupler" (the program that plays each role, in the same order: `[solid] program`, by default the
// role's own), "name: <scene name>", "steps: N" and "fluid_ranks: P" (`[fluid] ranks`, default 1:
// the ranks the launcher gives the fluid).
// Bad input: "ERROR: ..." on stderr and exit code 1.
#include <cstdio>
#include <string>

#include "runtime.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fsi-plan SCENE.toml\n");
    return 2;
  }
  try {
    const fsi::Scene scene(argv[1]);
    const auto root = scene.root();
    const auto roles = fsi::roles_needed(root);
    const auto common = fsi::read_common(root);
    // The solid role may be played by another program than `solid` (README, "Replacing a
    // solver"); the others by their own.
    std::string solid = "solid";
    if (roles.need[static_cast<int>(fsi::Role::solid)]) {
      const auto t = root.table("solid");
      if (t.has("program")) solid = t.choice("program", {"solid", "solid-rigid"});
    }
    long fluid_ranks = 1;
    if (roles.need[static_cast<int>(fsi::Role::fluid)]) {
      const auto t = root.table("fluid");
      if (t.has("ranks")) fluid_ranks = t.positive_integer("ranks");
    }
    for (const char* k : {"fluid", "solid", "fiber", "coupler"}) root.skip(k);
    root.finish();
    std::printf("roles:");
    for (int r = 0; r < fsi::kRoleCount; ++r)
      if (roles.need[r]) std::printf(" %s", fsi::role_name(static_cast<fsi::Role>(r)));
    std::printf("\nprograms:");
    for (int r = 0; r < fsi::kRoleCount; ++r)
      if (roles.need[r])
        std::printf(" %s", r == static_cast<int>(fsi::Role::solid)
                               ? solid.c_str()
                               : fsi::role_name(static_cast<fsi::Role>(r)));
    std::printf("\nname: %s\nsteps: %ld\nfluid_ranks: %ld\n", common.name.c_str(), common.steps,
                fluid_ranks);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ERROR: %s\n", e.what());
    return 1;
  }
  return 0;
}
