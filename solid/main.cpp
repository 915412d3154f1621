// The `solid` program: the finite-element solid solver, alone (a pure-solid scene) or as the
// solid role of a coupled MPMD job.
#include "program.hpp"
#include "runtime.hpp"

int main(int argc, char** argv) {
  return fsi::run_program(fsi::Role::solid, argc, argv, [](fsi::Runtime& rt) {
    solid::SolidProgram program(rt);
    fsi::serve(rt, program);
  });
}
