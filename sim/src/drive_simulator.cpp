#include "rpem/sim/drive_simulator.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/machine.hpp"
#include "rpem/core/units.hpp"

namespace rpem::sim {
namespace {

Magnetics make_magnetics(const Scenario& s) {
  if (s.flux_map_file.empty()) return Magnetics();
  return Magnetics(std::make_shared<const FluxMap>(FluxMap::load_csv(s.flux_map_file)));
}

double rpm_to_el_rad_s(double rpm, int pole_pairs) { return core::rpm_to_rad_s(rpm) * pole_pairs; }

}  // namespace

DriveSimulator::DriveSimulator(Scenario scenario)
    : scenario_(std::move(scenario)),
      plant_(scenario_.machine.machine.rated.pole_pairs, make_magnetics(scenario_), scenario_.mechanics),
      inverter_(scenario_.inverter),
      edges_(scenario_.inverter, scenario_.plant_tolerance),
      edge_to_edge_(scenario_.inverter.model == InverterModel::kSwitching &&
                    scenario_.integrator == PlantIntegrator::kEdges),
      foc_(scenario_.control, scenario_.machine.machine),
      sensors_(scenario_.sensors, scenario_.machine.machine.rated.pole_pairs, scenario_.sample_period_s, scenario_.seed),
      period_ns_(std::llround(scenario_.sample_period_s * 1e9)),
      samples_total_(std::llround(scenario_.duration_s / scenario_.sample_period_s)),
      warmup_periods_(std::llround(scenario_.warmup_s / scenario_.sample_period_s)),
      substeps_(static_cast<int>(std::lround(scenario_.sample_period_s / scenario_.plant_step_s))),
      regimes_(scenario_.regimes),
      thermal_(scenario_.thermal_plant.enabled
                   ? ThermalPlant(scenario_.thermal_plant, core::PerUnitBase::from_rated(scenario_.machine.machine.rated))
                   : ThermalPlant()) {
  // Start at the operating point of t = 0 (then settle over the warm-up).
  const int p = scenario_.machine.machine.rated.pole_pairs;
  parameters_ = parameters_at(-scenario_.warmup_s);
  const double omega = rpm_to_el_rad_s(scenario_.signal(Quantity::kSpeed).initial(), p);
  const core::PerUnitBase base = core::PerUnitBase::from_rated(scenario_.machine.machine.rated);
  const core::MachinePu nominal = core::to_pu(base, scenario_.machine.machine);
  const double torque0 = scenario_.control.speed_control ? 0.0 : scenario_.signal(Quantity::kTorque).initial();
  const core::Vec2 i0 = core::mtpa_reference(nominal, base.torque_pu(torque0)) * base.current_A;
  plant_.reset(i0, 0.0, omega, parameters_);
  // Prime the encoder history as if the machine had been turning at this speed.
  for (int j = scenario_.sensors.speed_window; j > 0; --j) (void)sensors_.angle(-j * omega * scenario_.sample_period_s);
  const core::Vec2 u0 = core::steady_state_voltage(nominal, base.speed_pu(omega), i0 / base.current_A) * base.voltage_V;
  command_now_V_ = command_next_V_ = core::inverse_park(u0, core::Rotation::of(0.0));
  u_dc_meas_V_ = u_dc_V_;
  duties_now_ = duties_next_ = modulate(command_now_V_, u_dc_V_, scenario_.inverter.third_harmonic_injection);
  u_dc_modulated_V_ = u_dc_V_;
  for (std::int64_t k = -warmup_periods_; k < 0; ++k) {
    sample_and_control(static_cast<double>(k) * scenario_.sample_period_s);
    integrate(k);
  }
}

PlantParameters DriveSimulator::parameters_at(double t_s) noexcept {
  Scenario& s = scenario_;
  const bool heated = s.thermal_plant.enabled;
  const double tw = heated ? thermal_.winding_C() : s.signal(Quantity::kTWinding).at(t_s);
  const double tm = heated ? thermal_.magnet_C() : s.signal(Quantity::kTMagnet).at(t_s);
  PlantParameters p;
  p.r_s_Ohm = s.signal(Quantity::kRs).at(t_s) * s.thermal.r_s.factor(tw);
  p.psi_m_Wb = s.signal(Quantity::kPsiM).at(t_s) * s.thermal.psi_m.factor(tm);
  p.l_d_H = s.signal(Quantity::kLd).at(t_s);
  p.l_q_H = s.signal(Quantity::kLq).at(t_s);
  p.r_fe_Ohm = s.r_fe_Ohm;
  torque_signal_Nm_ = s.signal(Quantity::kTorque).at(t_s);
  load_signal_Nm_ = s.separate_load ? s.signal(Quantity::kLoadTorque).at(t_s) : torque_signal_Nm_;
  u_dc_V_ = s.signal(Quantity::kUdc).at(t_s);
  t_winding_C_ = tw;
  t_magnet_C_ = tm;
  return p;
}

void DriveSimulator::update_regime(double t_s) noexcept {
  if (regimes_.empty()) return;
  const int p = scenario_.machine.machine.rated.pole_pairs;
  const RegimeNow now = regimes_.at(t_s);
  if (now.regime == DriveRegime::kOpenLoop && (regime_.regime != DriveRegime::kOpenLoop || now.event != regime_.event)) {
    // The commanded frame starts where the held current is in equilibrium with the load: its q axis (the
    // current's direction, s = the sign of the target speed) ahead of the rotor's d axis by the load angle δ0,
    // T = (3/2)·p·ψm·I·sin δ (surface magnets). The firmware starts at the observer's angle + 60° and lets
    // the lock time settle the rotor, which friction and iron losses damp on a real machine but nothing
    // damps in this plant.
    const RegimeEvent& e = regimes_.events()[static_cast<std::size_t>(now.event)];
    const double s = e.speed_rpm > 0.0 ? 1.0 : -1.0;
    const double load = scenario_.mechanics.dynamometer ? 0.0 : load_signal_Nm_;
    const double k = 1.5 * p * parameters_.psi_m_Wb * e.current_A;
    const double delta0 = std::asin(std::clamp(s * load / k, -0.95, 0.95));
    theta_frame_rad_ = plant_.state().theta_el_rad + s * (delta0 - 0.5 * core::kPi);
  }
  regime_ = now;
  omega_frame_rad_s_ = rpm_to_el_rad_s(now.open_loop_speed_rpm, p);
}

void DriveSimulator::sample_and_control(double t_s) noexcept {
  const int p = scenario_.machine.machine.rated.pole_pairs;
  parameters_ = parameters_at(t_s);
  const double speed_el = rpm_to_el_rad_s(scenario_.signal(Quantity::kSpeed).at(t_s), p);
  plant_.set_speed(speed_el);
  plant_.begin_period(parameters_, edge_to_edge_ ? scenario_.sample_period_s : scenario_.plant_step_s,
                      scenario_.mechanics.dynamometer ? 0.0 : load_signal_Nm_);
  update_regime(t_s);

  i_meas_A_ = sensors_.currents(plant_.phase_currents());
  theta_meas_rad_ = sensors_.angle(plant_.state().theta_el_rad);
  omega_meas_rad_s_ = sensors_.speed();
  u_dc_meas_V_ = sensors_.dc_link(u_dc_V_);
  if (regime_.regime == DriveRegime::kOpenLoop) {
    // The controller's frame is the commanded angle; the firmware's PLL, on that angle, reports its speed.
    theta_meas_rad_ = core::wrap_angle(theta_frame_rad_);
    omega_meas_rad_s_ = omega_frame_rad_s_;
    theta_frame_rad_ += omega_frame_rad_s_ * scenario_.sample_period_s;
  }

  // The command computed last period acts now; compute the next one. With an inverter delay δ < T the
  // command acts δ late: over this period the previous command holds for δ and this one for T − δ, in
  // volt-seconds (1 − δ/T)·u_k + (δ/T)·u_{k−1} — a transport delay under zero-order hold.
  const core::Vec2 command_before_V = command_now_V_;
  command_now_V_ = command_next_V_;
  duties_now_ = duties_next_;
  if (scenario_.inverter_delay_s > 0.0) {
    const double w = std::min(scenario_.inverter_delay_s / scenario_.sample_period_s, 1.0);
    duties_now_ = modulate((1.0 - w) * command_now_V_ + w * command_before_V, u_dc_modulated_V_,
                           scenario_.inverter.third_harmonic_injection);
  }
  FocInput in;
  in.i_abc_A = i_meas_A_;
  in.theta_el_rad = theta_meas_rad_;
  in.omega_el_rad_s = omega_meas_rad_s_;
  in.u_dc_V = u_dc_meas_V_;
  in.speed_control = regime_.control == ControlOverride::kScenario ? scenario_.control.speed_control
                                                                   : regime_.control == ControlOverride::kSpeed;
  in.torque_ref_Nm = in.speed_control ? 0.0 : torque_signal_Nm_;
  in.speed_ref_el_rad_s = speed_el;
  if (regime_.regime == DriveRegime::kOpenLoop) {
    const RegimeEvent& e = regimes_.events()[static_cast<std::size_t>(regime_.event)];
    in.current_override = true;
    in.current_ref_A = {0.0, e.speed_rpm > 0.0 ? e.current_A : -e.current_A};
    in.decouple = false;
  } else if (regime_.regime == DriveRegime::kBridgeOff) {
    // No current wanted; the integrators follow the back EMF the drive measures (the rotor frame's
    // (0, ω·ψm) at zero current, seen at the measured angle), so the command is ready for re-engaging.
    in.current_override = true;
    const PlantState& st = plant_.state();
    const core::Vec2 e_rotor(0.0, st.omega_el_rad_s * parameters_.psi_m_Wb);
    foc_.preset(core::park(e_rotor, core::Rotation::of(core::wrap_angle(theta_meas_rad_ - st.theta_el_rad))),
                omega_meas_rad_s_);
  }
  const FocOutput out = foc_.step(in);
  torque_cmd_Nm_ = out.torque_ref_Nm;
  command_next_V_ = out.u_ab_V;
  duties_next_ = modulate(out.u_ab_V, u_dc_meas_V_, scenario_.inverter.third_harmonic_injection);
  u_dc_modulated_V_ = u_dc_meas_V_;
}

void DriveSimulator::integrate(std::int64_t k) noexcept {
  if (regime_.regime == DriveRegime::kBridgeOff) {
    const PlantState& st = plant_.state();
    if (std::sqrt(3.0) * std::abs(st.omega_el_rad_s) * parameters_.psi_m_Wb >= u_dc_V_) ++rectifying_periods_;
    plant_.freewheel(edge_to_edge_ ? 1 : substeps_);
    return;
  }
  // The carrier valley is at even k (rising half), the peak at odd k.
  const bool rising = (k % 2) == 0;
  if (edge_to_edge_) {
    edges_.integrate(plant_, rising, duties_now_, u_dc_V_);
    return;
  }
  const double h = scenario_.plant_step_s;
  for (int s = 0; s < substeps_; ++s) {
    const double tau = s * h;
    plant_.step(inverter_.mean_voltage(rising, tau, h, duties_now_, plant_.phase_currents(), u_dc_V_));
  }
}

void DriveSimulator::fill_row(std::int64_t t_ns, io::DriveLogRow& row) const noexcept {
  core::DriveSample& s = row.sample;
  s.t_ns = t_ns;
  s.theta_el_rad = theta_meas_rad_;
  s.omega_el_rad_s = omega_meas_rad_s_;
  s.u_dc_V = u_dc_meas_V_;
  s.voltage_frame = core::Frame::kAbc;
  s.u_V = regime_.regime == DriveRegime::kBridgeOff ? core::Vec3::Zero() : core::inverse_clarke(command_now_V_);
  s.current_frame = core::Frame::kAbc;
  s.i_A = i_meas_A_;
  s.gap_before = false;
  constexpr double kNoReading = std::numeric_limits<double>::quiet_NaN();
  s.t_winding_C = scenario_.log.temperatures ? t_winding_C_ : kNoReading;
  row.t_magnet_C = scenario_.log.temperatures ? std::optional(t_magnet_C_) : std::nullopt;
  const bool coolant = scenario_.log.temperatures && scenario_.thermal_plant.enabled;
  s.t_coolant_C = coolant ? thermal_.coolant_C() : kNoReading;
  row.torque_cmd_Nm = scenario_.log.torque_cmd ? std::optional(torque_cmd_Nm_) : std::nullopt;
}

void DriveSimulator::fill_truth(std::int64_t t_ns, TruthRow& truth) const noexcept {
  const PlantState& st = plant_.state();
  truth.t_ns = t_ns;
  truth.parameters = parameters_;
  truth.omega_el_rad_s = st.omega_el_rad_s;
  truth.theta_el_rad = core::wrap_angle(st.theta_el_rad);
  truth.torque_Nm = st.torque_Nm;
  truth.i_dq_A = st.i_A;
  truth.t_winding_C = t_winding_C_;
  truth.t_magnet_C = t_magnet_C_;
  truth.regime = regime_.regime;
  truth.off_report = regime_.report;
  truth.theta_frame_rad = theta_meas_rad_;
  if (const FluxMap* map = plant_.magnetics().map()) {
    const core::Mat2 j = map->jacobian(st.i_A);  // differential inductances at the operating point
    truth.l_d_H = j(0, 0);
    truth.l_q_H = j(1, 1);
  } else {
    truth.l_d_H = parameters_.l_d_H;
    truth.l_q_H = parameters_.l_q_H;
  }
}

bool DriveSimulator::next(io::DriveLogRow& row, TruthRow& truth) noexcept {
  if (k_ >= samples_total_) return false;
  const double t_s = static_cast<double>(k_) * scenario_.sample_period_s;
  const std::int64_t t_ns = k_ * period_ns_;
  sample_and_control(t_s);
  fill_row(t_ns, row);
  fill_truth(t_ns, truth);
  // The losses at t_k, held over the period (the temperatures' time constants are minutes, the period µs).
  const bool heated = scenario_.thermal_plant.enabled;
  const PlantState& st = plant_.state();
  const double omega_el_rad_s = st.omega_el_rad_s;
  const ThermalLosses losses =
      heated ? thermal_.losses(st.i_A, st.psi_Wb, omega_el_rad_s, parameters_.r_s_Ohm) : ThermalLosses{};
  integrate(k_);
  if (heated) thermal_.step(losses, omega_el_rad_s, scenario_.sample_period_s);
  ++k_;
  return true;
}

io::DriveLogLayout DriveSimulator::layout() const noexcept {
  io::DriveLogLayout l;
  l.voltage_dq = l.current_dq = scenario_.log.dq_columns;
  l.t_winding = l.t_magnet = scenario_.log.temperatures;
  l.t_coolant = scenario_.log.temperatures && scenario_.thermal_plant.enabled;
  l.torque_cmd = scenario_.log.torque_cmd;
  return l;
}

}  // namespace rpem::sim
