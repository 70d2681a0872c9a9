#include "indep_drive/profile.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace indep {

OperatingProfile::OperatingProfile(std::vector<ProfilePoint> points) : points_(std::move(points)) {
  if (points_.empty()) throw std::invalid_argument("profile: no points");
  if (points_.front().t_s != 0.0) throw std::invalid_argument("profile: the first point must be at t = 0");
  for (std::size_t k = 1; k < points_.size(); ++k) {
    if (!(points_[k].t_s >= points_[k - 1].t_s)) {
      throw std::invalid_argument("profile: point " + std::to_string(k + 1) + " goes back in time");
    }
  }
}

ProfilePoint OperatingProfile::at(double t) const {
  // The last point at or before t, so that at a step time the later point holds.
  const auto after =
      std::upper_bound(points_.begin(), points_.end(), t, [](double v, const ProfilePoint& p) { return v < p.t_s; });
  if (after == points_.begin()) return points_.front();
  if (after == points_.end()) return points_.back();
  const ProfilePoint& a = *(after - 1);
  const ProfilePoint& b = *after;
  const double w = (t - a.t_s) / (b.t_s - a.t_s);
  auto mix = [w](double x, double y) { return x + w * (y - x); };
  return {t, mix(a.speed_rpm, b.speed_rpm), mix(a.torque_Nm, b.torque_Nm), mix(a.i_d_inject_A, b.i_d_inject_A)};
}

OperatingProfile default_profile(const MachineConfig& m, double duration, double max_speed_pu, double max_torque_pu) {
  // t / duration, speed / max_speed, torque / max_torque
  static constexpr double kTable[][3] = {
      {0.00, 0.0, 0.0},  {0.02, 0.0, 0.0},  {0.02, 0.0, 0.6},   {0.10, 0.0, 0.6},    // standstill under load
      {0.20, 0.6, 0.6},  {0.27, 0.6, 0.6},  {0.27, 0.6, -0.4},  {0.33, 0.6, -0.4},   // ramp, torque steps
      {0.33, 0.6, 1.0},  {0.40, 0.6, 1.0},  {0.48, 1.0, 0.5},   {0.56, 1.0, 0.5},    // ramp with torque ramp
      {0.64, -0.6, 0.5}, {0.70, -0.6, 0.5}, {0.70, -0.6, -0.7}, {0.77, -0.6, -0.7},  // reversal, motoring back
      {0.85, 0.3, 0.2},  {0.90, 0.9, 0.8},  {0.95, 0.9, 0.8},   {0.95, 0.9, 0.3},   {1.00, 0.9, 0.3}};
  const double speed = max_speed_pu * m.rated.speed_rpm;
  const double torque = max_torque_pu * m.torque_base_Nm();
  std::vector<ProfilePoint> points;
  for (const auto& row : kTable) points.push_back({row[0] * duration, row[1] * speed, row[2] * torque, 0.0});
  return OperatingProfile(std::move(points));
}

OperatingProfile read_profile_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot be read");
  std::string line;
  std::getline(in, line);
  std::vector<ProfilePoint> points;
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "\r") continue;
    std::stringstream ss(line);
    std::string cell;
    double v[4] = {0, 0, 0, 0};
    int n = 0;
    while (std::getline(ss, cell, ',') && n < 4) {
      try {
        std::size_t used = 0;
        v[n] = std::stod(cell, &used);
      } catch (const std::exception&) {
        throw std::runtime_error(path + ":" + std::to_string(line_no) + ": '" + cell + "' is not a number");
      }
      ++n;
    }
    if (n < 3) throw std::runtime_error(path + ":" + std::to_string(line_no) + ": expected t_s,speed_rpm,torque_Nm");
    points.push_back({v[0], v[1], v[2], v[3]});
  }
  try {
    return OperatingProfile(std::move(points));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

double TemperatureTrack::at(double t) const {
  if (end_C == start_C || tau_s <= 0.0) return start_C;
  return end_C + (start_C - end_C) * std::exp(-t / tau_s);
}

}  // namespace indep
