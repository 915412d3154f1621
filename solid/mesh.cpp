// Mesh bookkeeping: orientation and quality checks, surface edges, built-in rectangles, point
// location.
#include "mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include "error.hpp"

namespace solid {

namespace {

// An element whose area is below this fraction of its longest edge squared is degenerate
// (collinear nodes to round-off): its gradients would be meaningless.
constexpr double kDegenerateArea = 1e-12;

}  // namespace

bool Mesh::has_boundary(const std::string& name) const {
  return boundaries.count(name) > 0 || node_sets.count(name) > 0;
}

std::vector<int> Mesh::boundary_nodes(const std::string& name) const {
  std::vector<int> nodes;
  if (auto it = boundaries.find(name); it != boundaries.end())
    for (const auto& e : it->second) nodes.insert(nodes.end(), e.begin(), e.end());
  if (auto it = node_sets.find(name); it != node_sets.end())
    nodes.insert(nodes.end(), it->second.begin(), it->second.end());
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

std::vector<std::string> Mesh::boundary_names() const {
  std::vector<std::string> names;
  for (const auto& [k, v] : boundaries) names.push_back(k);
  for (const auto& [k, v] : node_sets) names.push_back(k);
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

int Mesh::region_index(const std::string& name) const {
  for (std::size_t r = 0; r < region_names.size(); ++r)
    if (region_names[r] == name) return static_cast<int>(r);
  return -1;
}

double Mesh::area() const {
  double a = 0;
  for (const auto& t : triangles) {
    const double* p = &x[2 * t[0]];
    const double* q = &x[2 * t[1]];
    const double* r = &x[2 * t[2]];
    a += 0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (r[0] - p[0]) * (q[1] - p[1]));
  }
  return a;
}

namespace {

double signed_area(const Mesh& m, const std::array<int, 3>& t) {
  const double* p = &m.x[2 * t[0]];
  const double* q = &m.x[2 * t[1]];
  const double* r = &m.x[2 * t[2]];
  return 0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (r[0] - p[0]) * (q[1] - p[1]));
}

double edge2(const Mesh& m, int a, int b) {
  const double dx = m.x[2 * b] - m.x[2 * a], dy = m.x[2 * b + 1] - m.x[2 * a + 1];
  return dx * dx + dy * dy;
}

std::uint64_t edge_key(int a, int b) {
  const auto lo = static_cast<std::uint64_t>(std::min(a, b));
  const auto hi = static_cast<std::uint64_t>(std::max(a, b));
  return lo << 32 | hi;
}

}  // namespace

MeshQuality finalize_mesh(Mesh& mesh, const std::vector<int>& orientation_group) {
  const int nt = mesh.num_triangles();
  if (nt == 0) throw fsi::InputError(fmt::format("mesh {} has no triangles", mesh.source));
  if (mesh.triangle_region.size() != mesh.triangles.size())
    mesh.triangle_region.assign(mesh.triangles.size(), 0);
  if (mesh.region_names.empty()) mesh.region_names.push_back("body");
  for (const auto& t : mesh.triangles)
    for (int a : t)
      if (a < 0 || a >= mesh.num_nodes())
        throw fsi::InputError(fmt::format("mesh {}: node index {} out of range", mesh.source, a));

  // Degenerate elements first: their orientation is meaningless.
  MeshQuality q;
  q.min_area = std::numeric_limits<double>::max();
  q.min_quality = std::numeric_limits<double>::max();
  q.min_edge = std::numeric_limits<double>::max();
  for (int e = 0; e < nt; ++e) {
    const auto& t = mesh.triangles[e];
    const double l0 = edge2(mesh, t[0], t[1]), l1 = edge2(mesh, t[1], t[2]),
                 l2 = edge2(mesh, t[2], t[0]);
    const double lmax = std::max({l0, l1, l2});
    const double a = std::abs(signed_area(mesh, t));
    if (!(a > kDegenerateArea * lmax))
      throw fsi::InputError(fmt::format(
          "mesh {}: element {} (nodes {}, {}, {}) is degenerate (area {:.3g}, longest edge {:.3g})",
          mesh.source, e, t[0], t[1], t[2], a, std::sqrt(lmax)));
    const double quality = 4 * std::sqrt(3.0) * a / (l0 + l1 + l2);
    if (quality < q.min_quality) {
      q.min_quality = quality;
      q.worst_triangle = e;
    }
    q.min_area = std::min(q.min_area, a);
    q.min_edge = std::min(q.min_edge, std::sqrt(std::min({l0, l1, l2})));
    q.max_edge = std::max(q.max_edge, std::sqrt(lmax));
  }

  // Orientation: the majority of each group decides; the minority is inverted.
  std::map<int, std::pair<int, int>> votes;  // group -> (counter-clockwise, clockwise)
  auto group_of = [&](int e) { return orientation_group.empty() ? 0 : orientation_group[e]; };
  for (int e = 0; e < nt; ++e) {
    auto& v = votes[group_of(e)];
    (signed_area(mesh, mesh.triangles[e]) > 0 ? v.first : v.second)++;
  }
  for (int e = 0; e < nt; ++e) {
    const auto& v = votes[group_of(e)];
    const bool group_ccw = v.first >= v.second;
    auto& t = mesh.triangles[e];
    const bool ccw = signed_area(mesh, t) > 0;
    if (ccw != group_ccw)
      throw fsi::InputError(fmt::format(
          "mesh {}: element {} (nodes {}, {}, {}) is inverted: its orientation is opposite to the "
          "{} other elements of its surface",
          mesh.source, e, t[0], t[1], t[2], group_ccw ? v.first : v.second));
    if (!ccw) std::swap(t[1], t[2]);
  }

  // Surface edges: edges of exactly one triangle, in the triangle's (counter-clockwise) order.
  std::unordered_map<std::uint64_t, std::pair<int, std::array<int, 2>>> count;
  count.reserve(3 * nt);
  for (int e = 0; e < nt; ++e) {
    const auto& t = mesh.triangles[e];
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      auto& c = count[edge_key(a, b)];
      c.first++;
      c.second = {a, b};
      if (c.first > 2)
        throw fsi::InputError(
            fmt::format("mesh {}: edge {}-{} is shared by more than two elements (element {})",
                        mesh.source, a, b, e));
    }
  }
  mesh.surface.clear();
  for (int e = 0; e < nt; ++e) {
    const auto& t = mesh.triangles[e];
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if (count[edge_key(a, b)].first == 1) mesh.surface.push_back({a, b});
    }
  }
  for (auto& [name, edges] : mesh.boundaries)
    for (auto& ed : edges)
      if (auto it = count.find(edge_key(ed[0], ed[1])); it != count.end() && it->second.first == 1)
        ed = it->second.second;
  return q;
}

Diagonals diagonals_from_name(const std::string& name) {
  if (name == "criss-cross") return Diagonals::criss_cross;
  if (name == "right") return Diagonals::right;
  if (name == "left") return Diagonals::left;
  if (name == "union-jack") return Diagonals::union_jack;
  throw std::invalid_argument("unknown diagonal pattern '" + name + "'");
}

Mesh rectangle_mesh(double x0, double y0, double lx, double ly, int nx, int ny, Diagonals d,
                    const std::string& region) {
  if (nx < 1 || ny < 1 || !(lx > 0) || !(ly > 0))
    throw std::invalid_argument("rectangle_mesh: need nx, ny >= 1 and positive sizes");
  Mesh m;
  m.source = fmt::format("rectangle {}x{} cells", nx, ny);
  m.region_names = {region};
  auto node = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      // Ends pinned exactly so that boundaries are straight to round-off.
      m.x.push_back(i == nx ? x0 + lx : x0 + lx * i / nx);
      m.x.push_back(j == ny ? y0 + ly : y0 + ly * j / ny);
    }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = node(i, j), b = node(i + 1, j), c = node(i + 1, j + 1), e = node(i, j + 1);
      if (d == Diagonals::union_jack) {
        const int centre = m.num_nodes();
        m.x.push_back(x0 + lx * (i + 0.5) / nx);
        m.x.push_back(y0 + ly * (j + 0.5) / ny);
        m.triangles.push_back({a, b, centre});
        m.triangles.push_back({b, c, centre});
        m.triangles.push_back({c, e, centre});
        m.triangles.push_back({e, a, centre});
        continue;
      }
      const bool rising =
          d == Diagonals::right || (d == Diagonals::criss_cross && (i + j) % 2 == 0);
      if (rising) {
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({a, c, e});
      } else {
        m.triangles.push_back({a, b, e});
        m.triangles.push_back({b, c, e});
      }
    }
  m.triangle_region.assign(m.triangles.size(), 0);
  auto& left = m.boundaries["left"];
  auto& right = m.boundaries["right"];
  auto& bottom = m.boundaries["bottom"];
  auto& top = m.boundaries["top"];
  for (int j = 0; j < ny; ++j) {
    left.push_back({node(0, j + 1), node(0, j)});
    right.push_back({node(nx, j), node(nx, j + 1)});
  }
  for (int i = 0; i < nx; ++i) {
    bottom.push_back({node(i, 0), node(i + 1, 0)});
    top.push_back({node(i + 1, ny), node(i, ny)});
  }
  finalize_mesh(m);
  return m;
}

MeshPoint locate(const Mesh& mesh, double px, double py, double tol) {
  MeshPoint best;
  double best_min = -std::numeric_limits<double>::max();
  for (int e = 0; e < mesh.num_triangles(); ++e) {
    const auto& t = mesh.triangles[e];
    const double* p = &mesh.x[2 * t[0]];
    const double* q = &mesh.x[2 * t[1]];
    const double* r = &mesh.x[2 * t[2]];
    const double a2 = (q[0] - p[0]) * (r[1] - p[1]) - (r[0] - p[0]) * (q[1] - p[1]);
    const double w1 = ((px - p[0]) * (r[1] - p[1]) - (r[0] - p[0]) * (py - p[1])) / a2;
    const double w2 = ((q[0] - p[0]) * (py - p[1]) - (px - p[0]) * (q[1] - p[1])) / a2;
    const double w0 = 1 - w1 - w2;
    const double mn = std::min({w0, w1, w2});
    if (mn > best_min) {
      best_min = mn;
      best.triangle = e;
      best.weights = {w0, w1, w2};
    }
  }
  if (best_min < -tol) best.triangle = -1;
  return best;
}

}  // namespace solid
