// A test-only program that serves a solver role with empty physics: no grid cells that move, no
// bodies, no fibers. It exercises the runtime and the protocol independently of the real solvers
// (the protocol tests launch it as `null_solver ROLE SCENE`).
#include <string>

#include "driver.hpp"

namespace {

class NullFluid : public fsi::FluidPort {
 public:
  fsi::proto::GridInfo grid_info() const override {
    fsi::proto::GridInfo g;
    g.nx = g.ny = 4;
    for (int i = 0; i <= 4; ++i) g.x_face.push_back(0.25 * i), g.y_face.push_back(0.25 * i);
    g.density = 1;
    return g;
  }
  void advance(const fsi::proto::StepBegin&, const fsi::proto::FluidInput& in,
               fsi::proto::FluidOutput& out) override {
    out.fs_u.assign(in.solid_u.index.size(), 0.0);
    out.fs_v.assign(in.solid_v.index.size(), 0.0);
    out.u_sample.assign(in.sample_u.size(), 0.0);
    out.v_sample.assign(in.sample_v.size(), 0.0);
  }
  void output(long, double, bool) override {}
};

class NullSolid : public fsi::SolidPort {
 public:
  fsi::proto::BodyMeshes meshes() const override { return {}; }
  void state(fsi::proto::SolidState& s) const override { s = {}; }
  void advance(const fsi::proto::StepBegin&, const fsi::proto::SolidInput&) override {}
  void output(long, double, bool) override {}
};

class NullFiber : public fsi::FiberPort {
 public:
  fsi::proto::FiberLayout layout() const override { return {}; }
  void set_initial_roots(const std::vector<std::vector<double>>&) override {}
  void state(fsi::proto::FiberState& s) const override { s = {}; }
  void advance(const fsi::proto::StepBegin&, const fsi::proto::FiberInput&) override {}
  void output(long, double, bool) override {}
};

}  // namespace

int main(int argc, char** argv) {
  const std::string name = argc > 1 ? argv[1] : "";
  const auto role = fsi::role_from_name(name);
  if (!role || *role == fsi::Role::coupler) {
    std::fprintf(stderr, "usage: null_solver fluid|solid|fiber SCENE.toml [options]\n");
    return 2;
  }
  return fsi::run_program(*role, argc - 1, argv + 1, [&](fsi::Runtime& rt) {
    for (const char* k : {"fluid", "solid", "fiber"}) rt.root().skip(k);
    if (*role == fsi::Role::fluid) {
      NullFluid p;
      fsi::serve(rt, p);
    } else if (*role == fsi::Role::solid) {
      NullSolid p;
      fsi::serve(rt, p);
    } else {
      NullFiber p;
      fsi::serve(rt, p);
    }
  });
}
