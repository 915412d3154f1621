// What the fiber unit tests share: fiber specs, Euler-Bernoulli cantilever modes, zero crossings
// and periods of sampled signals.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "spec.hpp"
#include "system.hpp"

namespace fiber::test {

inline FiberSpec make_fiber(double length, int segments, double density, double bending, Vec2 position = {0, 0},
                            double angle = 0) {
  FiberSpec f;
  f.name = std::string("f");
  f.key = std::string("fiber.fiber[0]");
  f.length = length;
  f.segments = segments;
  f.density = density;
  f.bending = bending;
  f.position = position;
  f.angle = angle;
  return f;
}

inline Config one_fiber(const FiberSpec& f) {
  Config c;
  c.fibers.push_back(f);
  return c;
}

// Euler-Bernoulli clamped-free mode k (1-based): beta_k L and the shape phi(s) with phi' below.
inline double cantilever_beta(int k) {
  const double b[] = {1.875104068711961, 4.694091132974175, 7.854757438237613};
  return b[k - 1];
}
inline double cantilever_mode(int k, double s, double length) {
  const double b = cantilever_beta(k) / length;
  const double bl = cantilever_beta(k);
  const double sigma = (std::cosh(bl) + std::cos(bl)) / (std::sinh(bl) + std::sin(bl));
  return std::cosh(b * s) - std::cos(b * s) - sigma * (std::sinh(b * s) - std::sin(b * s));
}
inline double cantilever_mode_slope(int k, double s, double length) {
  const double b = cantilever_beta(k) / length;
  const double bl = cantilever_beta(k);
  const double sigma = (std::cosh(bl) + std::cos(bl)) / (std::sinh(bl) + std::sin(bl));
  return b * (std::sinh(b * s) + std::sin(b * s) - sigma * (std::cosh(b * s) - std::cos(b * s)));
}

// Markers of a fiber along x deflected by eps * phi_k, built from the tangent angle so that
// every segment has length ds exactly.
inline std::vector<Vec2> cantilever_shape(int k, double eps, double length, int segments) {
  const double ds = length / segments;
  std::vector<Vec2> p(segments + 1, Vec2::Zero());
  for (int j = 0; j < segments; ++j) {
    const double psi = std::atan(eps * cantilever_mode_slope(k, (j + 0.5) * ds, length));
    p[j + 1] = p[j] + ds * Vec2(std::cos(psi), std::sin(psi));
  }
  return p;
}

// Times where a sampled signal changes sign (linear interpolation).
inline std::vector<double> zero_crossings(const std::vector<double>& t, const std::vector<double>& y) {
  std::vector<double> z;
  for (std::size_t i = 1; i < y.size(); ++i)
    if ((y[i - 1] < 0) != (y[i] < 0)) z.push_back(t[i - 1] + (t[i] - t[i - 1]) * y[i - 1] / (y[i - 1] - y[i]));
  return z;
}

// Mean period from the zero crossings (two per period), over whole periods only so that an
// offset of the signal's mean does not bias it.
inline double period_from_crossings(const std::vector<double>& z) {
  if (z.size() < 3) return NAN;
  const std::size_t last = z.size() - 1 - (z.size() - 1) % 2;
  return 2 * (z[last] - z.front()) / static_cast<double>(last);
}

}  // namespace fiber::test
