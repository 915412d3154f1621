// Surface probes ([[coupler.surface_probe]], coupler_surface.csv): the wall shear stress at
// material points of a body's surface (paper Eq. 30, tau = mu t . (grad u + grad u^T) . n) and
// the pressure there, taken on the fluid side from velocity and pressure samples the coupler asks
// the fluid for (common/PROTOCOL.md, sample_u/sample_v/sample_p), never from the forced velocity
// inside the body.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "protocol.hpp"

namespace coupler {

namespace proto = fsi::proto;

struct SurfaceProbeSpec {
  std::string name;
  std::string body;              // empty: the body whose surface is nearest to `point`
  std::array<double, 2> point;   // on the body's surface in its reference configuration
};

// The method, per probe, from a body state (positions x, velocities v of its nodes):
//   surface point  p = x_a + s (x_b − x_a) on the surface edge a -> b that holds the material
//                  point (body on the left of a -> b), outward normal n = (e_y, −e_x) with
//                  e = (x_b − x_a)/|x_b − x_a|, tangent t = (n_y, −n_x) (t = +x on a surface
//                  facing +y, as the fluid's wall_shear on the bottom side);
//   fluid points   q_k = p + d_k n, d_k = (kFirst + k) h, k = 0, 1, 2, h = the larger grid
//                  spacing at p: each bilinear stencil (its faces' control volumes) lies wholly
//                  outside a flat surface at any angle, so no forced face enters;
//   u(q_k)         bilinear interpolation of the sampled MAC faces;
//   tau = mu [ d(u.t)/dn + d(u.n)/dt ],
//     d(u.t)/dn    the derivative at d = 0 of the parabola through (d_k, u(q_k).t): the fluid's
//                  own profile extrapolated to the surface (exact for Couette and Poiseuille
//                  profiles); the wall value is not used: the immersed solid places the wall the
//                  flow sees up to half a cell from the true one (runs/sub-cell-wall), which a
//                  one-sided difference to the true wall would divide by a cell;
//     d(u.n)/dt    along the no-slip surface, that of the body's velocity: −(v_b − v_a).n / L.
// Also written: the slip u_s = u.t extrapolated to the surface minus the body's v.t there (zero
// for an exact no-slip wall; it measures where the flow sees the wall), and the pressure
//   p = (d_1 p(q_0) − d_0 p(q_1)) / (d_1 − d_0),  p(q_k) bilinear in the cell centres,
// the line through the two nearest fluid points extrapolated to the surface: exact for a linear
// pressure (away from a domain wall: within half a cell of one the nearest row's value is taken),
// O(h^2) where p is smooth (at a no-slip wall dp/dn = mu d^2 u_n/dn^2 stays finite); on a flat
// surface the pressure inside the body and in the cells the interface cuts is not used.
class SurfaceProbes {
 public:
  // The probes' edges on the bodies' reference surfaces. An unknown body, or a point farther
  // from the surface than kOnSurface of the nearest edge's length, is an fsi::InputError naming
  // the key, the probe, the body and the distance (source: the scene file, for the message).
  SurfaceProbes(const proto::GridInfo& grid, const proto::BodyMeshes& meshes,
                std::vector<SurfaceProbeSpec> specs, double viscosity, const std::string& source);

  // Columns of coupler_surface.csv: <name>.x, .y, .nx, .ny, .tau, .slip, .p per probe.
  std::vector<std::string> columns() const;

  // Merge the faces and cells of every probe's stencils in `state` into the sorted lists u_faces,
  // v_faces and p_cells (kept sorted and unique; idempotent).
  void add_requests(const proto::SolidState& state, std::vector<std::int32_t>& u_faces,
                    std::vector<std::int32_t>& v_faces, std::vector<std::int32_t>& p_cells);

  // The row (columns() order) from the fluid's samples of u^(n+1) on the requested faces and of
  // p^(n+1) in the requested cells, with the surface in `state` (the configuration the fluid's
  // forcing used). A stencil face or cell missing from the samples is an error (the request was
  // not sent).
  void evaluate(const proto::SolidState& state, const std::vector<std::int32_t>& u_faces,
                const std::vector<double>& u, const std::vector<std::int32_t>& v_faces,
                const std::vector<double>& v, const std::vector<std::int32_t>& p_cells,
                const std::vector<double>& p, std::vector<double>& row);

  // Values per probe in a row.
  static constexpr int kColumns = 7;

  std::size_t size() const { return m_probes.size(); }

  // The first fluid point, in grid spacings from the surface, and the number of points.
  static constexpr double kFirst = 2.5;
  static constexpr int kPoints = 3;

 private:
  struct Probe {
    SurfaceProbeSpec spec;
    int body = 0, a = 0, b = 0;
    double s = 0;
  };
  // One direction of a face family: node coordinates, periodic period (0: bounded).
  struct Axis1 {
    std::vector<double> c;
    double period = 0;
  };
  struct Family {
    Axis1 x, y;
    std::vector<double> value;
    std::vector<char> has;
  };
  struct Frame {
    double px, py, nx, ny, h;
    double vt, dvn_dt;  // the body's tangential velocity at p, d(v.n)/dt along the surface
  };
  Frame frame(const Probe& p, const proto::SolidState& state) const;
  // Bilinear stencil of (x, y) on a family: 4 flat face indices and weights.
  void stencil(const Family& f, double x, double y, std::int32_t idx[4], double w[4]) const;
  double interpolate(const Family& f, double x, double y) const;

  std::vector<Probe> m_probes;
  double m_mu;
  std::vector<double> m_xf, m_yf;
  Family m_u, m_v, m_p;
  std::vector<std::int32_t> m_scratch;
};

}  // namespace coupler
