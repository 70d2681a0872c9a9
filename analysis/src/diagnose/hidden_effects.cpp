#include "rpem/analysis/diagnose/hidden_effects.hpp"

#include <cmath>
#include <stdexcept>

#include "rpem/sim/drive_simulator.hpp"

namespace rpem::analysis {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

/// A torque/speed profile as fractions of rated torque and speed: (duration share, speed, torque).
struct Segment {
  double share;
  double speed;
  double torque;
};

// Standstill at three currents of both signs, then low and high speed in both directions with torque of
// both signs; speeds move by ramps (a dynamometer holds them), torques by steps.
const Segment kProfile[] = {
    {0.08, 0.0, 0.3},  {0.08, 0.0, 0.7},   {0.08, 0.0, -0.5}, {0.08, 0.3, 0.4},  {0.08, 0.3, -0.4},
    {0.08, 0.7, 0.2},  {0.08, 0.7, 0.6},   {0.08, -0.5, 0.3}, {0.08, -0.5, -0.3}, {0.08, -0.15, 0.5},
    {0.1, 0.0, 0.2},   {0.1, 0.9, 0.15},
};

void add_profile(sim::Scenario& s, double speed_rated_rpm, double torque_rated_Nm) {
  double t = 0.0;
  const double ramp = 0.25 * s.duration_s * 0.08;
  s.signal(sim::Quantity::kSpeed) = sim::Signal(kProfile[0].speed * speed_rated_rpm);
  s.signal(sim::Quantity::kTorque) = sim::Signal(kProfile[0].torque * torque_rated_Nm);
  for (std::size_t i = 1; i < std::size(kProfile); ++i) {
    t += kProfile[i - 1].share * s.duration_s;
    if (kProfile[i].speed != kProfile[i - 1].speed) {
      s.signal(sim::Quantity::kSpeed).add({t, sim::EventKind::kRamp, kProfile[i].speed * speed_rated_rpm, ramp});
    }
    s.signal(sim::Quantity::kTorque).add({t, sim::EventKind::kStep, kProfile[i].torque * torque_rated_Nm, 0.0});
  }
}

double uniform(std::mt19937_64& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
double sign(std::mt19937_64& rng) { return std::bernoulli_distribution(0.5)(rng) ? 1.0 : -1.0; }

}  // namespace

sim::Scenario diagnose_profile(double duration_s, std::uint64_t seed) {
  sim::Scenario s = sim::paper_scenario();
  s.name = "diagnose-profile";
  s.duration_s = duration_s;
  s.seed = seed;
  s.inverter.model = sim::InverterModel::kSwitching;
  s.sensors.current_noise_A = 0.02;
  s.sensors.current_lsb_A = 0.005;
  s.sensors.encoder_counts = 16384;
  s.sensors.u_dc_noise_V = 0.5;
  s.sensors.u_dc_lsb_V = 0.1;
  s.signal(sim::Quantity::kUdc) = sim::Signal(565.0);
  const core::MachineSi& m = s.machine.machine;
  add_profile(s, m.rated.speed_rpm, core::PerUnitBase::from_rated(m.rated).torque_Nm);
  return s;
}

sim::Scenario flux_map_profile(const std::string& machine_yaml, const std::string& flux_map_csv, double duration_s,
                               std::uint64_t seed) {
  sim::Scenario s = sim::paper_scenario();
  s.name = "diagnose-flux-map";
  s.machine = io::load_machine_config(machine_yaml);
  s.flux_map_file = flux_map_csv;
  s.duration_s = duration_s;
  s.seed = seed;
  s.inverter.model = sim::InverterModel::kSwitching;
  s.control.max_current_A = 8.0;  // the measured map's range
  s.sensors.current_noise_A = 0.005;
  s.sensors.current_lsb_A = 0.002;
  s.sensors.encoder_counts = 16384;
  const core::MachineSi& m = s.machine.machine;
  s.signal(sim::Quantity::kPsiM) = sim::Signal(m.psi_m_Wb);
  s.signal(sim::Quantity::kRs) = sim::Signal(m.r_s_Ohm);
  s.signal(sim::Quantity::kLd) = sim::Signal(m.l_d_H);
  s.signal(sim::Quantity::kLq) = sim::Signal(m.l_q_H);
  s.signal(sim::Quantity::kUdc) = sim::Signal(48.0);
  // Torque as a share of what 8 A gives: the map's full current range is used.
  add_profile(s, m.rated.speed_rpm, 1.5 * m.rated.pole_pairs * m.psi_m_Wb * 8.0 / 0.9);
  return s;
}

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

}  // namespace rpem::analysis
