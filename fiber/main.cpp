// The `fiber` program: inextensible fibers with tension, bending and repulsion, alone (a fiber
// scene in vacuum) or as the fiber role of a coupled MPMD job.
#include "program.hpp"
#include "runtime.hpp"

int main(int argc, char** argv) {
  return fsi::run_program(fsi::Role::fiber, argc, argv, [](fsi::Runtime& rt) {
    fiber::FiberProgram program(rt);
    fsi::serve(rt, program);
  });
}
