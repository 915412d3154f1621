// Face and centre coordinates, ghost mirroring and the stencil coefficients of the MAC grid.
#include "grid.hpp"

#include <cmath>

#include "error.hpp"

namespace fluid {

Axis::Axis(const AxisSpec& s) : m_n(s.cells + s.sponge_cells), m_periodic(s.periodic) {
  if (s.cells < 1 || !(s.length > 0))
    fsi::fail("fluid::Axis: an axis needs cells >= 1 and a length > 0, got {} cells over {}",
              s.cells, s.length);
  const int n = m_n;
  std::vector<double> f(n + 1);
  for (int i = 0; i <= s.cells; ++i) {
    const double xi = double(i) / s.cells;
    double x = s.length * xi;
    if (s.tanh_beta > 0) {
      x = 0.5 * s.length * (1.0 + std::tanh(s.tanh_beta * (2 * xi - 1)) / std::tanh(s.tanh_beta));
    }
    f[i] = s.origin + x;
  }
  f[0] = s.origin;
  f[s.cells] = s.origin + s.length;
  double w = f[s.cells] - f[s.cells - 1];
  for (int i = s.cells + 1; i <= n; ++i) {
    w *= s.sponge_ratio;
    f[i] = f[i - 1] + w;
  }
  m_sponge_start = s.sponge_cells > 0 ? s.cells : n;
  m_uniform = s.tanh_beta <= 0 && (s.sponge_cells == 0 || s.sponge_ratio == 1.0);

  // Widths with two ghost cells per side: mirrored, or wrapped around when periodic.
  auto width = [&](int i) {
    if (i >= 0 && i < n) return f[i + 1] - f[i];
    if (m_periodic) {
      const int k = ((i % n) + n) % n;
      return f[k + 1] - f[k];
    }
    const int k = i < 0 ? -1 - i : 2 * n - 1 - i;  // mirror image
    return f[k + 1] - f[k];
  };
  m_face.assign(n + 3, 0);
  m_centre.assign(n + 2, 0);
  for (int i = 0; i <= n; ++i) m_face[i + 1] = f[i];
  m_face[0] = f[0] - width(-1);
  m_face[n + 2] = f[n] + width(n);
  for (int i = -1; i <= n; ++i) m_centre[i + 1] = 0.5 * (face(i) + face(i + 1));

  m_w.assign(n + 2, 0);
  m_wi.assign(n + 2, 0);
  m_ci.assign(n + 2, 0);
  for (int i = -1; i <= n; ++i) {
    m_w[i + 1] = width(i);
    m_wi[i + 1] = 1.0 / width(i);
    // centre(i+1) - centre(i-1) = (w(i-1) + 2 w(i) + w(i+1)) / 2
    m_ci[i + 1] = 4.0 / (width(i - 1) + 2 * width(i) + width(i + 1));
  }
  m_di.assign(n + 3, 0);
  m_wlo.assign(n + 3, 0);
  m_whi.assign(n + 3, 0);
  for (int i = -1; i <= n + 1; ++i) {
    const double a = width(i - 1), b = width(i);
    m_di[i + 1] = 2.0 / (a + b);
    m_wlo[i + 1] = b / (a + b);
    m_whi[i + 1] = a / (a + b);
  }
}

}  // namespace fluid
