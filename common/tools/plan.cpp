// fsi-plan SCENE.toml: what the launcher needs to compose the mpirun line, read with the same
// strict rules as the programs. Prints "roles: fluid solid coupler" and "name: <scene name>".
// Bad input: "ERROR: ..." on stderr and exit code 1.
#include <cstdio>

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
    for (const char* k : {"fluid", "solid", "fiber", "coupler"}) root.skip(k);
    root.finish();
    std::printf("roles:");
    for (int r = 0; r < fsi::kRoleCount; ++r)
      if (roles.need[r]) std::printf(" %s", fsi::role_name(static_cast<fsi::Role>(r)));
    std::printf("\nname: %s\nsteps: %ld\n", common.name.c_str(), common.steps);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ERROR: %s\n", e.what());
    return 1;
  }
  return 0;
}
