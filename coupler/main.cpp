// The coupler program: the clock of a coupled run and every transfer between the solvers.
#include "coupler.hpp"
#include "runtime.hpp"

int main(int argc, char** argv) {
  return fsi::run_program(fsi::Role::coupler, argc, argv, [](fsi::Runtime& rt) {
    coupler::Coupler c(rt);
    c.run();
  });
}
