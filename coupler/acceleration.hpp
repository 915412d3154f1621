// IQN-ILS (Degroote et al. 2009), the acceleration of the coupled iterations: the next estimate of
// the fixed point x = H(x) of one coupled step from the secant pairs of its iterations (and of
// previous steps'). README.md, "Coupled iterations".
#pragma once

#include <string>
#include <vector>

#include "h5.hpp"

namespace coupler {

// [coupler.iterations]: sub-iterations of the coupled step (README.md, "Coupled iterations").
struct IterationSettings {
  int max = 1;              // sub-iterations per step; 1: the explicit staggered step
  double tolerance = 1e-6;  // on ||v^(k+1) - v^(k)|| relative to ||v^(k+1)||
  double relaxation = 0.5;  // the update without secant columns (the first of a step): x + w r
  int reuse = 0;            // previous steps whose secant pairs are kept
};

// x: the stacked nodal velocities of the elastic bodies at t^(n+1); H: one pass fluid forcing +
// projection -> reaction -> solid step. Each update() takes the input x^k and its image
// x~^k = H(x^k), with the residual r^k = x~^k - x^k, and gives the next input
//   x^(k+1) = x~^k + W c,  c = argmin |V c + r^k|,
// with the columns V_i = r^(i+1) - r^i, W_i = x~^(i+1) - x~^i of this step (newest first), then
// of `reuse` previous steps: W c is the least-squares inverse Jacobian of the residual on the span
// of V. Without columns (k = 0 and nothing reused): x^(k+1) = x^k + relaxation r^k.
class Acceleration {
 public:
  // A column whose part orthogonal to the newer columns is below this fraction of its length
  // says nothing they do not, and would make the least squares ill-conditioned: dropped.
  static constexpr double kFilter = 1e-3;
  explicit Acceleration(const IterationSettings& s) : m_s(s) {}
  void begin_step();
  void update(const std::vector<double>& x, const std::vector<double>& xt,
              std::vector<double>& next);
  // The step is over: a converged step's secant pairs join the kept ones (reuse); a step that did
  // not converge clears them all.
  void end_step(bool converged);
  // The kept secant pairs of previous steps (between steps), in a checkpoint's group `group`.
  void save(fsi::H5File& h5, const std::string& group) const;
  void load(const fsi::H5File& h5, const std::string& group);
  double omega() const { return m_s.relaxation; }  // the relaxation of an update without columns
  int columns() const { return m_columns; }        // columns used by the last update

 private:
  struct Pairs {  // secant pairs of one step, newest first
    std::vector<std::vector<double>> v, w;
  };
  IterationSettings m_s;
  int m_k = 0;
  int m_columns = 0;
  std::vector<double> m_r_prev, m_xt_prev;
  Pairs m_now;
  std::vector<Pairs> m_old;  // previous steps, newest first
};

}  // namespace coupler
