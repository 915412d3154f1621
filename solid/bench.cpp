// bench_solid: the cost of the solid solver on the Turek-Hron bar (about 3 900 nodes, as the
// paper's Table 2, and two refinements by 2 in each direction): Newmark steps under gravity
// (the bar of CSM1 released from rest), time per Newton iteration split into assembly,
// factorisation and solve, per step, and how it grows with the node count. Writes JSON to
// --out FILE and prints a table.
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "gmsh_mesh.hpp"
#include "solver.hpp"

using namespace solid;

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

int main(int argc, char** argv) {
  std::string out = "solid.json";
  int steps = 20;
  LinearSolver::Backend backend = LinearSolver::Backend::automatic;
  for (int k = 1; k < argc; ++k) {
    if (!std::strcmp(argv[k], "--out") && k + 1 < argc)
      out = argv[++k];
    else if (!std::strcmp(argv[k], "--steps") && k + 1 < argc)
      steps = std::stoi(argv[++k]);
    else if (!std::strcmp(argv[k], "--backend") && k + 1 < argc)
      backend = std::string(argv[++k]) == "cholmod" ? LinearSolver::Backend::cholmod
                                                    : LinearSolver::Backend::ldlt;
  }
  nlohmann::json j;
  j["case"] =
      "Turek-Hron bar (CSM1 material, gravity 2), Newmark dt = 0.005 from rest, criss-cross mesh";
  j["steps_per_level"] = steps;
  j["levels"] = nlohmann::json::array();
  fmt::print(
      "{:>7} {:>7} {:>6} {:>6} | per Newton iteration [ms]: {:>8} {:>8} {:>8} {:>8} | {:>9} {:>9} "
      "| {:>8}\n",
      "nodes", "eqs", "steps", "iters", "assembly", "factor", "solve", "total", "per step", "setup",
      "ns/node");
  std::vector<std::pair<double, double>> scaling;
  for (int level : {1, 2, 4}) {
    const int ny = 12 * level, nx = 300 * level;
    const double t0 = now();
    GmshOptions opt;
    opt.parameters = {{"nx", nx}, {"ny", ny}};
    Model model;
    model.settings.gravity = {0, -2};
    BodySpec bar;
    bar.name = "bar";
    bar.mesh =
        read_gmsh(std::filesystem::path(FSI_SOURCE_DIR) / "runs/turek-hron-csm/bar.geo", opt);
    const double t_mesh = now() - t0;
    Material m =
        Material::from_young(MaterialModel::saint_venant_kirchhoff, 2 * 0.5e6 * 1.4, 0.4, 1000);
    bar.materials = {m};
    Constraint c;
    c.boundary = "clamp";
    bar.constraints = {c};
    model.bodies = {bar};
    const double t1 = now();
    Solver s(model, backend);
    const double t_setup = now() - t1;
    double assembly = 0, factor = 0, solve = 0, wall = 0;
    long iters = 0;
    for (int k = 0; k < steps; ++k) {
      const double ts = now();
      const StepReport r = s.advance(0.005);
      wall += now() - ts;
      assembly += r.assembly_seconds;
      factor += r.factor_seconds;
      solve += r.solve_seconds;
      iters += r.iterations;
    }
    const int nodes = s.mesh(0).num_nodes();
    const double per_it = (assembly + factor + solve) / iters;
    nlohmann::json l;
    l["nodes"] = nodes;
    l["linear_solver"] = s.linear_backend();
    l["triangles"] = s.mesh(0).num_triangles();
    l["equations"] = s.num_equations();
    l["elements_across"] = ny;
    l["steps"] = steps;
    l["newton_iterations"] = iters;
    l["per_iteration_s"] = {{"assembly", assembly / iters},
                            {"factorization", factor / iters},
                            {"solve", solve / iters},
                            {"total", per_it}};
    l["per_step_s"] = wall / steps;
    l["setup_s"] = t_setup;
    l["mesh_s"] = t_mesh;
    l["ns_per_node_iteration"] = 1e9 * per_it / nodes;
    j["levels"].push_back(l);
    scaling.push_back({std::log(double(nodes)), std::log(per_it)});
    fmt::print(
        "{:>7} {:>7} {:>6} {:>6} | {:>26} {:>8.2f} {:>8.2f} {:>8.2f} {:>8.2f} | {:>9.2f} {:>9.2f} "
        "| {:>8.0f}\n",
        nodes, s.num_equations(), steps, iters, "", 1e3 * assembly / iters, 1e3 * factor / iters,
        1e3 * solve / iters, 1e3 * per_it, 1e3 * wall / steps, 1e3 * t_setup, 1e9 * per_it / nodes);
  }
  // Growth exponent p of the time per iteration ~ nodes^p between the levels.
  nlohmann::json growth = nlohmann::json::array();
  for (std::size_t k = 1; k < scaling.size(); ++k)
    growth.push_back((scaling[k].second - scaling[k - 1].second) /
                     (scaling[k].first - scaling[k - 1].first));
  j["growth_exponent_per_iteration"] = growth;
  fmt::print("time per Newton iteration grows as nodes^p, p = {}\n", growth.dump());
  std::ofstream(out) << j.dump(2) << "\n";
  fmt::print("written {}\n", out);
  return 0;
}
