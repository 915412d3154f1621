// The feedback immersed boundary transfers for fibers (paper Sec. 3.2.2; Huang & Sung 2009):
// interpolation of the fluid velocity to the markers and spreading of marker forces to the faces
// of the staggered grid with Peskin's 4-point delta, as exact transposes of each other.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "protocol.hpp"

namespace coupler {

namespace proto = fsi::proto;

// Peskin's 4-point kernel φ(r) (Peskin 2002, Acta Numerica 11, Eq. 6.27):
//   |r| <= 1:     (3 − 2|r| + sqrt(1 + 4|r| − 4r²)) / 8
//   1 <= |r| <= 2: (5 − 2|r| − sqrt(−7 + 12|r| − 4r²)) / 8
// Σ_i φ(r − i) = 1 and Σ_i (r − i) φ(r − i) = 0 for every r, so constants and linear fields are
// interpolated exactly and spreading conserves force.
double peskin4(double r);

// The four weights φ(r + 1), φ(r), φ(r − 1), φ(r − 2) of the points i0 .. i0 + 3 around a point
// at i0 + 1 + r, r in [0, 1). With q = sqrt(1 + 4r − 4r²) they are (3 − 2r − q)/8,
// (3 − 2r + q)/8, (1 + 2r + q)/8, (1 + 2r − q)/8 (the radicands of both branches of φ at these
// four distances are the same): one square root for all four.
void peskin4_weights(double r, double w[4]);

class FeedbackIB {
 public:
  // The grid must be uniform in each direction where fibers are (checked here for the whole
  // grid: the delta function's moment conditions hold on a uniform grid only).
  explicit FeedbackIB(const proto::GridInfo& grid);
  // The grid is uniform in both directions (what the constructor needs).
  static bool uniform_grid(const proto::GridInfo& grid);

  // The u- and v-faces within the kernels of markers x (interleaved), dilated by `margin` cells,
  // sorted: the faces whose velocity the coupler asks the fluid for. Faces on a non-periodic
  // boundary are included (they hold boundary values).
  void stencil(const std::vector<std::vector<double>>& markers, int margin,
               std::vector<std::int32_t>& u_faces, std::vector<std::int32_t>& v_faces);

  // Remember sampled face velocities (the fluid's answer to a stencil request).
  void store_samples(const std::vector<std::int32_t>& u_faces, const std::vector<double>& u,
                     const std::vector<std::int32_t>& v_faces, const std::vector<double>& v);

  // U(X) = Σ_faces u_f φ((x_f − X)/h_x) φ((y_f − Y)/h_y) at each marker, from stored samples. A
  // face of the kernel that was not sampled is an error (a marker moved more than the margin).
  void interpolate(const std::vector<double>& x, std::vector<double>& u) const;

  // The force per unit volume on the fluid from forces per unit length F on the markers of one
  // fiber of spacing ds: f(x_f) = −Σ_m F_m w_m φ(..)φ(..)/(h_x h_y), with the marker's arclength
  // w_m = ds inside and ds/2 at the two ends (the weights the fiber integrates its loads with, so
  // that action = reaction), accumulated per face.
  void spread(const std::vector<double>& x, const std::vector<double>& F, double ds);
  // The feedback force of one fiber in one pass over its markers (feedback.cpp, Eq. 23-25): at
  // each marker the kernels of X_m, U(X_m) from the stored samples, the force per unit length
  //   F_m = κ (Δt U(X_m) − (X_m − X_old,m))
  // into F, and F_m spread as spread() does: the same sums, in the same order, as interpolate(),
  // the force and spread(), with one kernel evaluation per marker.
  void feedback(const std::vector<double>& x, const std::vector<double>& x_old, double kappa,
                double dt, double ds, std::vector<double>& F);
  // The accumulated spread force as sparse face lists (sorted), then cleared. u_faces, v_faces:
  // a stencil() (any margin) of every marker spread since the last take: it holds every face
  // they touched.
  void take_spread(const std::vector<std::int32_t>& u_faces,
                   const std::vector<std::int32_t>& v_faces, proto::FaceForce& u,
                   proto::FaceForce& v);

  double hx() const { return m_hx; }
  double hy() const { return m_hy; }

 private:
  struct Family {
    int ni = 0, nj = 0;          // faces along x, y; flat index i + ni*j
    double x0 = 0, y0 = 0;       // position of face (0, 0)
    bool px = false, py = false; // periodic
    // Per face, and one slot more, `outside` = ni·nj: the kernels' faces beyond a bounded
    // side, with value 0, always sampled, its spread force dropped; so that interpolation and
    // spreading run without a branch per face.
    std::vector<double> value;   // sampled velocity per face
    std::vector<char> has_value;
    std::vector<double> force;  // spread force per face, until take_spread()
    std::vector<char> mark;     // face listed (within stencil() only)
    // The last stencil(): its windows' cells (i, j per window, kFiberEnd twice after each
    // fiber), margin and faces; and the scratch for the next call's cells.
    std::vector<int> windows, window_scratch;
    int window_margin = -1;
    std::vector<std::int32_t> window_faces;
  };
  // Marks the end of a fiber in Family::windows: no cell index is this low (stencil() refuses a
  // marker more than kFarCells cells from the grid's origin).
  static constexpr int kFiberEnd = std::numeric_limits<int>::min();
  static constexpr double kFarCells = 1e9;
  // The 4 × 4 kernel of a point on one family: the face columns and the row offsets (ni · row)
  // it spans (−1 beyond a bounded side) and the weights along x and y; `inner` when none is
  // beyond a side (face (a, b) is then col[a] + row[b]).
  struct Kernel {
    int col[4], row[4];
    double wx[4], wy[4];
    bool inner;
  };
  // The kernels of point (X, Y) on the u faces (k[0]) and the v faces (k[1]).
  void kernel(double X, double Y, Kernel k[2]) const;
  static std::int32_t face(const Family& f, const Kernel& K, int a, int b);
  static double gather(const Family& f, const Kernel& K, char& sampled);
  static void scatter(Family& f, const Kernel& K, double t);
  // A clear error for a marker that is not finite or too far off for the kernels' integers.
  void check_marker(double X, double Y) const;
  // The error of a marker whose kernel reaches a face that was not sampled.
  [[noreturn]] static void unsampled(double X, double Y);

  double m_hx, m_hy, m_ihx, m_ihy, m_lx, m_ly;
  Family m_u, m_v;
};

}  // namespace coupler
