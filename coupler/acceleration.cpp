// IQN-ILS, the acceleration of the coupled iterations (acceleration.hpp).
#include "acceleration.hpp"

#include <Eigen/Core>
#include <Eigen/QR>
#include <cmath>
#include <utility>

#include "checkpoint.hpp"

namespace coupler {

void Acceleration::begin_step() {
  m_k = 0;
  m_now = {};
  m_columns = 0;
}

void Acceleration::save(fsi::H5File& h5, const std::string& group) const {
  h5.write(group + "/steps", std::vector<std::int64_t>{static_cast<std::int64_t>(m_old.size())});
  for (std::size_t k = 0; k < m_old.size(); ++k) {
    fsi::write_vectors(h5, fmt::format("{}/{}/v", group, k), m_old[k].v);
    fsi::write_vectors(h5, fmt::format("{}/{}/w", group, k), m_old[k].w);
  }
}

void Acceleration::load(const fsi::H5File& h5, const std::string& group) {
  m_old.assign(static_cast<std::size_t>(h5.read_int64s(group + "/steps").at(0)), {});
  for (std::size_t k = 0; k < m_old.size(); ++k) {
    m_old[k].v = fsi::read_vectors(h5, fmt::format("{}/{}/v", group, k));
    m_old[k].w = fsi::read_vectors(h5, fmt::format("{}/{}/w", group, k));
  }
}

void Acceleration::end_step(bool converged) {
  if (m_s.reuse == 0) return;
  // A step that did not converge may hold nearly dependent pairs (a steady state: differences of
  // velocities at the tolerance's floor) that would steer the next steps' least squares far off:
  // forget every kept pair and start the next step from the relaxation alone.
  if (!converged) {
    m_old.clear();
    m_now = {};
    return;
  }
  if (!m_now.v.empty()) m_old.insert(m_old.begin(), std::move(m_now));
  if (static_cast<int>(m_old.size()) > m_s.reuse) m_old.resize(static_cast<std::size_t>(m_s.reuse));
  m_now = {};
}

void Acceleration::update(const std::vector<double>& x, const std::vector<double>& xt,
                          std::vector<double>& next) {
  const std::size_t n = x.size();
  std::vector<double> r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = xt[i] - x[i];
  next.resize(n);
  if (m_k > 0) {
    std::vector<double> dv(n), dw(n);
    for (std::size_t i = 0; i < n; ++i) dv[i] = r[i] - m_r_prev[i], dw[i] = xt[i] - m_xt_prev[i];
    m_now.v.insert(m_now.v.begin(), std::move(dv));
    m_now.w.insert(m_now.w.begin(), std::move(dw));
  }
  m_r_prev = r;
  m_xt_prev = xt;
  ++m_k;

  // The columns, newest first: this step's, then the kept steps'. Filter: modified Gram-Schmidt
  // (twice) against the kept ones; a column below kFilter is dropped for good.
  std::vector<std::pair<Pairs*, std::size_t>> cols;
  std::vector<std::vector<double>> q;
  auto consider = [&](Pairs& p) {
    for (std::size_t c = 0; c < p.v.size();) {
      if (q.size() >= n) {  // as many columns as unknowns: the rest cannot help
        p.v.erase(p.v.begin() + c), p.w.erase(p.w.begin() + c);
        continue;
      }
      std::vector<double> a = p.v[c];
      double len = 0;
      for (double z : a) len += z * z;
      len = std::sqrt(len);
      for (int pass = 0; pass < 2; ++pass)
        for (const auto& b : q) {
          double d = 0;
          for (std::size_t i = 0; i < n; ++i) d += a[i] * b[i];
          for (std::size_t i = 0; i < n; ++i) a[i] -= d * b[i];
        }
      double rest = 0;
      for (double z : a) rest += z * z;
      rest = std::sqrt(rest);
      if (!(len > 0) || rest < kFilter * len) {
        p.v.erase(p.v.begin() + c), p.w.erase(p.w.begin() + c);
        continue;
      }
      for (double& z : a) z /= rest;
      q.push_back(std::move(a));
      cols.push_back({&p, c});
      ++c;
    }
  };
  consider(m_now);
  for (auto& p : m_old) consider(p);
  m_columns = static_cast<int>(cols.size());
  if (cols.empty()) {
    for (std::size_t i = 0; i < n; ++i) next[i] = x[i] + m_s.relaxation * r[i];
    return;
  }
  // c = argmin |V c + r| by Householder QR; x^(k+1) = x~^k + W c.
  const Eigen::Index m = static_cast<Eigen::Index>(cols.size());
  Eigen::MatrixXd V(static_cast<Eigen::Index>(n), m);
  for (Eigen::Index j = 0; j < m; ++j) {
    const auto& col = cols[j].first->v[cols[j].second];
    for (std::size_t i = 0; i < n; ++i) V(static_cast<Eigen::Index>(i), j) = col[i];
  }
  const Eigen::Map<const Eigen::VectorXd> rv(r.data(), static_cast<Eigen::Index>(n));
  const Eigen::VectorXd c = V.householderQr().solve(-rv);
  next = xt;
  for (Eigen::Index j = 0; j < m; ++j) {
    const auto& w = cols[j].first->w[cols[j].second];
    for (std::size_t i = 0; i < n; ++i) next[i] += c[j] * w[i];
  }
}

}  // namespace coupler
