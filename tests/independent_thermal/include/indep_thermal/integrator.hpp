#pragma once
// Adaptive Dormand-Prince 5(4) (Dormand and Prince 1980; Hairer, Nørsett and Wanner, Solving ODEs I,
// II.4-5): the 5th-order solution is propagated, the embedded 4th-order one estimates the error, and the step
// follows h·min(5, max(0.2, 0.9·err^(−1/5))). advance() ends exactly at t_end (the last step clipped), so a
// caller stops at every knot of its inputs and at every output instant; the first stage is evaluated anew
// after each stop, since the inputs may step there.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace indep_thermal {

struct StepControl {
  double rtol = 1e-8;
  double atol = 1e-8;
  double max_step = std::numeric_limits<double>::infinity();
  int error_states = -1;  // only the first n states enter the error norm (−1: all)
};

struct StepStats {
  long accepted = 0;
  long rejected = 0;
  long evaluations = 0;
};

template <int N>
class DormandPrince {
 public:
  using Vector = Eigen::Matrix<double, N, 1>;

  explicit DormandPrince(StepControl control) : control_(control) {}

  /// Integrates dy/dt = f(t, y) from t to t_end; on return t = t_end. `f` is callable as f(double, const Vector&).
  template <class F>
  void advance(F&& f, double& t, double t_end, Vector& y) {
    if (!(t_end >= t)) throw std::invalid_argument("DormandPrince::advance: t_end before t");
    if (t_end == t) return;
    Vector k1 = f(t, y);
    ++stats_.evaluations;
    if (h_ <= 0.0) h_ = std::min(control_.max_step, t_end - t);
    while (t < t_end) {
      double h = std::min({h_, control_.max_step, t_end - t});
      // Avoid a sliver of a last step: stretch this one to t_end when within 1e-12 of it.
      const bool last = t + h >= t_end - 1e-12 * std::max(1.0, std::abs(t_end));
      if (last) h = t_end - t;
      const Vector k2 = f(t + h * (1.0 / 5), y + h * (1.0 / 5) * k1);
      const Vector k3 = f(t + h * (3.0 / 10), y + h * ((3.0 / 40) * k1 + (9.0 / 40) * k2));
      const Vector k4 = f(t + h * (4.0 / 5), y + h * ((44.0 / 45) * k1 - (56.0 / 15) * k2 + (32.0 / 9) * k3));
      const Vector k5 = f(t + h * (8.0 / 9), y + h * ((19372.0 / 6561) * k1 - (25360.0 / 2187) * k2 + (64448.0 / 6561) * k3 -
                                                      (212.0 / 729) * k4));
      const Vector k6 = f(t + h, y + h * ((9017.0 / 3168) * k1 - (355.0 / 33) * k2 + (46732.0 / 5247) * k3 +
                                          (49.0 / 176) * k4 - (5103.0 / 18656) * k5));
      const Vector y5 =
          y + h * ((35.0 / 384) * k1 + (500.0 / 1113) * k3 + (125.0 / 192) * k4 - (2187.0 / 6784) * k5 + (11.0 / 84) * k6);
      const Vector k7 = f(t + h, y5);
      stats_.evaluations += 6;
      const Vector err = h * ((71.0 / 57600) * k1 - (71.0 / 16695) * k3 + (71.0 / 1920) * k4 - (17253.0 / 339200) * k5 +
                              (22.0 / 525) * k6 - (1.0 / 40) * k7);
      const int n = control_.error_states < 0 ? static_cast<int>(y.size()) : control_.error_states;
      double sum = 0.0;
      for (int i = 0; i < n; ++i) {
        const double scale = control_.atol + control_.rtol * std::max(std::abs(y(i)), std::abs(y5(i)));
        sum += (err(i) / scale) * (err(i) / scale);
      }
      const double e = std::sqrt(sum / n);
      if (!std::isfinite(e)) throw std::runtime_error("DormandPrince: the state is not finite");
      const double factor = e == 0.0 ? 5.0 : std::clamp(0.9 * std::pow(e, -0.2), 0.2, 5.0);
      if (e <= 1.0) {
        t = last ? t_end : t + h;
        y = y5;
        k1 = k7;  // first same as last
        ++stats_.accepted;
        // A last step clipped short says little about the step the next interval can take: keep the proposal
        // unless the clipped step itself asks for less.
        if (last && h < h_) {
          if (factor < 1.0) h_ = std::min(h_, h * factor);
        } else {
          h_ = h * factor;
        }
      } else {
        ++stats_.rejected;
        h_ = h * std::min(1.0, factor);
        if (h_ < 1e-12 * std::max(1.0, std::abs(t))) throw std::runtime_error("DormandPrince: step size underflow");
      }
    }
  }

  [[nodiscard]] const StepStats& stats() const { return stats_; }

 private:
  StepControl control_;
  StepStats stats_;
  double h_ = 0.0;
};

}  // namespace indep_thermal
