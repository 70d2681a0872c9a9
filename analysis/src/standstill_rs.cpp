#include "rpem/analysis/standstill_rs.hpp"

#include <cmath>
#include <cstdint>

namespace rpem::analysis {

namespace {

/// One sample of the recursion: updates R (relative to (i/r_s)²) and x.
void step(const StandstillRs& m, double& x, double& r) {
  const double psi = -1.0 / ((1.0 + x) * (1.0 + x));  // Ψ / (i/r_s)
  const double eps = x / (1.0 + x);                   // ε / i
  r = (1.0 - m.gamma_r) * r + m.gamma_r * psi * psi;
  x += m.gamma_L * psi * eps / r;
}

}  // namespace

std::optional<double> standstill_rs_time_s(const StandstillRs& m, double initial_error, double band, double horizon_s) {
  const auto horizon = static_cast<std::int64_t>(horizon_s / m.sample_period_s);
  double x = initial_error;
  double r = m.hessian0_rel;
  for (std::int64_t k = 0; k <= horizon; ++k) {
    if (std::abs(x) <= band) return static_cast<double>(k) * m.sample_period_s;
    if (!(x > -1.0) || !std::isfinite(x)) return std::nullopt;
    step(m, x, r);
  }
  return std::nullopt;
}

double standstill_rs_error_after(const StandstillRs& m, double initial_error, double time_s) {
  double x = initial_error;
  double r = m.hessian0_rel;
  const auto samples = static_cast<std::int64_t>(std::llround(time_s / m.sample_period_s));
  for (std::int64_t k = 0; k < samples && x > -1.0 && std::isfinite(x); ++k) step(m, x, r);
  return x;
}

std::optional<double> linearised_rs_bound_s(double gamma_r, double gamma_L, double sample_period_s, double initial_error,
                                            double band, double horizon_s) {
  const auto horizon = static_cast<std::int64_t>(horizon_s / sample_period_s);
  double e = std::abs(initial_error);
  double forget = 1.0;  // (1 − γ_r)^k
  for (std::int64_t k = 0; k <= horizon; ++k) {
    if (e <= band) return static_cast<double>(k) * sample_period_s;
    forget *= 1.0 - gamma_r;
    e *= 1.0 - gamma_L / (1.0 - forget);
  }
  return std::nullopt;
}

std::optional<double> standstill_rs_initial_error_for(const StandstillRs& m, double time_s, double band) {
  auto slower = [&](double e0) {
    const auto t = standstill_rs_time_s(m, e0, band, 2.0 * time_s + 1.0);
    return !t || *t > time_s;
  };
  double lo = band, hi = 1.0;
  if (slower(lo * (1.0 + 1e-9))) return std::nullopt;
  if (!slower(hi)) return std::nullopt;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (slower(mid) ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace rpem::analysis
