// The `fluid` program: the Navier-Stokes solver on the fixed grid, alone (a pure-flow scene) or
// as the fluid role of a coupled MPMD job.
#include "program.hpp"
#include "runtime.hpp"

int main(int argc, char** argv) {
  return fsi::run_program(fsi::Role::fluid, argc, argv, [](fsi::Runtime& rt) {
    fluid::FluidProgram program(rt);
    fsi::serve(rt, program);
  });
}
