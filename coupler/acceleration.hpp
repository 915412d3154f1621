// The acceleration of the coupled iterations: the next estimate of the fixed point x = H(x) of
// one coupled step from the iterations so far (README.md, "Coupled iterations").
#pragma once

#include <vector>

namespace coupler {

// [coupler.iterations]: sub-iterations of the coupled step (README.md, "Coupled iterations").
struct IterationSettings {
  enum class Method { constant, aitken, iqn_ils };
  int max = 1;              // sub-iterations per step; 1: the explicit staggered step
  double tolerance = 1e-6;  // on ||v^(k+1) - v^(k)|| relative to ||v^(k+1)||
  Method method = Method::iqn_ils;
  double relaxation = 0.5;  // the first (constant, Aitken: initial) relaxation factor
  int reuse = 0;            // IQN-ILS: previous steps whose secant pairs are kept
};

// The acceleration of the fixed point x = H(x) of one coupled step, x the stacked nodal
// velocities of the elastic bodies at t^(n+1) and H one pass fluid forcing + projection ->
// reaction -> solid step. Each update() takes the input x^k and its image x~^k = H(x^k) and
// gives the next input x^(k+1). Methods (r^k = x~^k - x^k):
//  constant: x^(k+1) = x^k + w r^k.
//  aitken:   the same with w_k = -w_(k-1) r^(k-1).(r^k - r^(k-1)) / |r^k - r^(k-1)|^2 (Irons-Tuck;
//            Kuettler & Wall 2008), |w_k| <= kAitkenMax; w_0 = relaxation every step.
//  iqn_ils:  Degroote et al. 2009: with columns V_i = r^(i+1) - r^i, W_i = x~^(i+1) - x~^i
//            (this step's, newest first, then those of `reuse` previous steps), c = argmin
//            |V c + r^k| (Eigen Householder QR on the columns kept), x^(k+1) = x~^k + W c: the
//            least-squares inverse Jacobian of the residual on the span of V. A column whose part
//            orthogonal to the newer ones is below kFilter of its length is dropped. Without
//            columns (k = 0 and nothing reused): constant relaxation.
class Acceleration {
 public:
  static constexpr double kAitkenMax = 2.0;
  static constexpr double kFilter = 1e-3;
  explicit Acceleration(const IterationSettings& s) : m_s(s) {}
  void begin_step();
  void update(const std::vector<double>& x, const std::vector<double>& xt, std::vector<double>& next);
  // The step is over: a converged step's secant pairs join the kept ones (IQN-ILS, reuse); a
  // step that did not converge clears them all.
  void end_step(bool converged);
  double omega() const { return m_omega; }
  int columns() const { return m_columns; }  // columns used by the last IQN-ILS update

 private:
  struct Pairs {  // secant pairs of one step, newest first
    std::vector<std::vector<double>> v, w;
  };
  IterationSettings m_s;
  int m_k = 0;
  double m_omega = 0;
  int m_columns = 0;
  std::vector<double> m_r_prev, m_xt_prev;
  Pairs m_now;
  std::vector<Pairs> m_old;  // previous steps, newest first
};

}  // namespace coupler
