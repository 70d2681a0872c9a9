#include "hidden_effects/hidden_effects.hpp"

#include <cmath>
#include <stdexcept>

#include "rpem/sim/drive_simulator.hpp"

namespace rpem::test {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

double uniform(std::mt19937_64& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
double sign(std::mt19937_64& rng) { return std::bernoulli_distribution(0.5)(rng) ? 1.0 : -1.0; }

}  // namespace

void hide(sim::Scenario& s, const HiddenEffect& e) {
  const double t_end = s.duration_s;
  if (e.name == "none") {
  } else if (e.name == "deadtime") {
    s.inverter.dead_time_s = e.value;
  } else if (e.name == "theta_offset") {
    s.sensors.theta_offset_rad = e.value;  // measured = true − offset: the true angle is logged + offset
  } else if (e.name == "current_offset") {
    s.sensors.current_offset_A[e.phase] = e.value;
  } else if (e.name == "current_gain") {
    s.sensors.current_gain_error[e.phase] = e.value;
  } else if (e.name == "rs_drift") {
    s.signal(sim::Quantity::kTWinding).add({0.0, sim::EventKind::kRamp, s.thermal.reference_C + e.value, t_end});
    s.log.temperatures = e.temperatures_logged;
  } else if (e.name == "psim_drift") {
    s.signal(sim::Quantity::kTMagnet).add({0.0, sim::EventKind::kRamp, s.thermal.reference_C + e.value, t_end});
    s.log.temperatures = e.temperatures_logged;
  } else if (e.name == "delay") {
    s.inverter_delay_s = e.value;
  } else if (e.name == "iron_loss") {
    s.r_fe_Ohm = e.value;
  } else {
    throw std::invalid_argument("no way to hide effect '" + e.name + "'");
  }
}

HiddenEffect draw_effect(std::mt19937_64& rng, const sim::Scenario& s, const std::string& name) {
  HiddenEffect e;
  e.name = name;
  const core::PerUnitBase base = core::PerUnitBase::from_rated(s.machine.machine.rated);
  if (name == "deadtime") {
    e.value = uniform(rng, 0.5e-6, 3e-6);
  } else if (name == "theta_offset") {
    e.value = sign(rng) * uniform(rng, 1.0, 6.0) * kDeg;
  } else if (name == "current_offset") {
    e.phase = std::uniform_int_distribution<int>(0, 2)(rng);
    e.value = sign(rng) * uniform(rng, 0.005, 0.03) * base.current_A;
  } else if (name == "current_gain") {
    e.phase = std::uniform_int_distribution<int>(0, 2)(rng);
    e.value = sign(rng) * uniform(rng, 0.01, 0.04);
  } else if (name == "rs_drift" || name == "psim_drift") {
    e.value = uniform(rng, 20.0, 60.0);
    e.temperatures_logged = std::bernoulli_distribution(0.5)(rng);
  } else if (name == "delay") {
    e.value = uniform(rng, 15e-6, 60e-6);
  } else if (name == "iron_loss") {
    e.value = uniform(rng, 20.0, 60.0) * base.impedance_Ohm;
  } else if (name != "none") {
    throw std::invalid_argument("no way to draw effect '" + name + "'");
  }
  return e;
}

std::vector<io::DriveLogRow> simulate(const sim::Scenario& s, io::DriveLogLayout* layout) {
  sim::DriveSimulator sim(s);
  if (layout) *layout = sim.layout();
  std::vector<io::DriveLogRow> rows;
  rows.reserve(static_cast<std::size_t>(sim.samples_total()));
  io::DriveLogRow row;
  sim::TruthRow truth;
  while (sim.next(row, truth)) rows.push_back(row);
  return rows;
}

}  // namespace rpem::test
