// Initial velocity fields of [fluid.initial], projected to be divergence-free.
#include <cmath>
#include <numbers>

#include "solver.hpp"

namespace fluid {

void set_initial(Solver& s) {
  const Initial& in = s.config().initial;
  const Grid& g = s.grid();
  const int nx = g.nx();
  const double pi = std::numbers::pi;
  auto velocity = [&](double x, double y) -> std::array<double, 2> {
    switch (in.type) {
      case InitialType::rest:
        return {0, 0};
      case InitialType::uniform:
        return in.velocity;
      case InitialType::taylor_green: {
        const double kx = 2 * pi / g.x().length(), ky = 2 * pi / g.y().length();
        const double X = x - g.x().lo(), Y = y - g.y().lo();
        return {-in.amplitude * std::cos(kx * X) * std::sin(ky * Y),
                in.amplitude * (kx / ky) * std::sin(kx * X) * std::cos(ky * Y)};
      }
      case InitialType::vortex: {
        const double dx = x - in.centre[0], dy = y - in.centre[1];
        const double r2 = (dx * dx + dy * dy) / (in.radius * in.radius);
        const double w = in.amplitude / in.radius * std::exp(0.5 * (1 - r2));  // v_theta / r
        return {in.velocity[0] - w * dy, in.velocity[1] + w * dx};
      }
    }
    return {0, 0};
  };
  // The rows this rank holds (all of them on one rank).
  const Decomposition& d = s.decomposition();
  for (int j = d.lo(); j < d.hi(); ++j)
    for (int i = 0; i <= nx; ++i) s.u()(i, j) = velocity(g.x().face(i), g.y().centre(j))[0];
  for (int j = d.lo(); j < d.v_hi(); ++j)
    for (int i = 0; i < nx; ++i) s.v()(i, j) = velocity(g.x().centre(i), g.y().face(j))[1];
  s.project_initial();
}

}  // namespace fluid
