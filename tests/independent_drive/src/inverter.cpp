#include "indep_drive/inverter.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "indep_drive/frames.hpp"

namespace indep {

Modulation modulation_from_name(std::string_view name) {
  if (name == "sine") return Modulation::sine;
  if (name == "third_harmonic") return Modulation::third_harmonic;
  if (name == "space_vector") return Modulation::space_vector;
  throw std::invalid_argument("modulation '" + std::string(name) + "': expected sine, third_harmonic or space_vector");
}

const char* modulation_name(Modulation m) {
  switch (m) {
    case Modulation::sine:
      return "sine";
    case Modulation::third_harmonic:
      return "third_harmonic";
    case Modulation::space_vector:
      return "space_vector";
  }
  return "?";
}

double linear_limit_V(double u_dc, Modulation m) { return m == Modulation::sine ? 0.5 * u_dc : u_dc / kSqrt3; }

std::array<double, 3> duty_cycles(const std::array<double, 3>& u, double u_dc, Modulation m) {
  double u0 = 0.0;
  if (m == Modulation::space_vector) {
    u0 = -0.5 * (std::max({u[0], u[1], u[2]}) + std::min({u[0], u[1], u[2]}));
  } else if (m == Modulation::third_harmonic) {
    const Vec2 ab = clarke(u);
    const double amplitude = ab.norm();
    u0 = -amplitude / 6.0 * std::cos(3.0 * std::atan2(ab.y, ab.x));
  }
  std::array<double, 3> d{};
  for (std::size_t k = 0; k < 3; ++k) d[k] = std::clamp(0.5 + (u[k] + u0) / u_dc, 0.0, 1.0);
  return d;
}

DelayLine::DelayLine(double delay_periods) {
  if (!(delay_periods >= 0.0) || delay_periods >= kMaxPeriods) {
    throw std::invalid_argument("delay: " + std::to_string(delay_periods) + " control periods, expected [0, 4)");
  }
  whole_ = static_cast<int>(std::floor(delay_periods));
  fraction_ = delay_periods - whole_;
  for (auto& d : ring_) d = {0.5, 0.5, 0.5};  // before the first issue the legs sit at zero voltage
}

void DelayLine::push(const std::array<double, 3>& duties) {
  head_ = (head_ + 1) % ring_.size();
  ring_[head_] = duties;
}

const std::array<double, 3>& DelayLine::issued_ago(int periods) const {
  return ring_[(head_ + ring_.size() - static_cast<std::size_t>(periods)) % ring_.size()];
}

const std::array<double, 3>& DelayLine::first() const { return issued_ago(whole_ + 1); }
const std::array<double, 3>& DelayLine::second() const { return issued_ago(whole_); }

}  // namespace indep
