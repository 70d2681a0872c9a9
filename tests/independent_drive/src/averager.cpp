#include "indep_drive/averager.hpp"

#include <algorithm>

namespace indep {

IntervalAverager::IntervalAverager(double mean, double jitter, double min_s, double max_s, std::uint64_t seed)
    : mean_(mean), jitter_(jitter), min_(min_s), max_(max_s), rng_(seed) {
  end_ = next_length();
}

double IntervalAverager::next_length() {
  const double u = std::uniform_real_distribution<double>(-1.0, 1.0)(rng_);
  return std::clamp(mean_ * (1.0 + jitter_ * u), min_, max_);
}

void IntervalAverager::close_window() {
  if (weight_ > 0.0) {
    AveragedRow r;
    r.t_s = end_;
    r.t_start_s = start_;
    double* fields[8] = {&r.i_d_A,          &r.i_q_A,  &r.u_d_V,       &r.u_q_V,
                         &r.omega_el_rad_s, &r.u_dc_V, &r.T_winding_C, &r.T_magnet_C};
    for (std::size_t k = 0; k < 8; ++k) *fields[k] = sum_[k] / weight_;
    rows_.push_back(r);
  }
  sum_ = {};
  weight_ = 0.0;
  start_ = end_;
  end_ = start_ + next_length();
}

void IntervalAverager::add_segment(double t0, const AveragedSample& y0, double t1, const AveragedSample& y1) {
  const double span = t1 - t0;
  if (!(span > 0.0)) return;
  auto at = [&](double t) {
    AveragedSample y;
    const double w = (t - t0) / span;
    for (std::size_t k = 0; k < y.size(); ++k) y[k] = y0[k] + w * (y1[k] - y0[k]);
    return y;
  };
  double a = t0;
  AveragedSample ya = y0;
  while (a < t1) {
    const double b = std::min(t1, end_);
    const AveragedSample yb = b == t1 ? y1 : at(b);
    for (std::size_t k = 0; k < sum_.size(); ++k) sum_[k] += 0.5 * (b - a) * (ya[k] + yb[k]);
    weight_ += b - a;
    a = b;
    ya = yb;
    if (b >= end_) close_window();
  }
}

void IntervalAverager::add_sample(double t, const AveragedSample& y) {
  while (t >= end_) close_window();
  for (std::size_t k = 0; k < sum_.size(); ++k) sum_[k] += y[k];
  weight_ += 1.0;
}

}  // namespace indep
