#include "rpem/sim/scenario.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <system_error>
#include <utility>

namespace rpem::sim {
namespace {

namespace fs = std::filesystem;
constexpr double kHuge = 1e12;

std::string resolve(const std::string& base_dir, const std::string& path) {
  if (path.empty() || fs::path(path).is_absolute() || base_dir.empty()) return path;
  return (fs::path(base_dir) / path).lexically_normal().string();
}

void parse_inverter(io::YamlMap m, Scenario& s) {
  s.inverter.model = m.choice_or("model", "switching", {"switching", "averaged"}) == "averaged" ? InverterModel::kAveraged
                                                                                                : InverterModel::kSwitching;
  s.inverter.switching_frequency_Hz = m.number_or("switching_frequency_Hz", 4000.0, 100.0, 1e6);
  s.inverter.dead_time_s = m.number_or("dead_time_s", 0.0, 0.0, 1e-4);
  s.inverter.v_igbt_V = m.number_or("v_igbt_V", 0.0, 0.0, 100.0);
  s.inverter.v_diode_V = m.number_or("v_diode_V", 0.0, 0.0, 100.0);
  s.inverter.third_harmonic_injection = m.boolean_or("third_harmonic", true);
  s.inverter_delay_s = m.number_or("delay_s", 0.0, 0.0, 1e-3);
  if (s.inverter_delay_s >= s.sample_period_s) m.fail("delay_s", "must be below the sample period");
  m.finish();
}

void parse_plant(io::YamlMap m, Scenario& s, const std::string& base_dir) {
  const bool averaged = s.inverter.model == InverterModel::kAveraged;
  const std::string integrator = m.choice_or("integrator", averaged ? "fixed" : "edges", {"edges", "fixed"});
  s.integrator = integrator == "edges" ? PlantIntegrator::kEdges : PlantIntegrator::kFixedStep;
  if (averaged && s.integrator == PlantIntegrator::kEdges) m.fail("integrator", "edges needs inverter.model: switching");
  if (s.integrator == PlantIntegrator::kFixedStep) {
    s.plant_step_s = m.number_or("step_s", averaged ? s.sample_period_s : 1e-6, 1e-9, s.sample_period_s);
  } else if (m.has("step_s")) {
    m.fail("step_s", "applies to integrator: fixed (the default, edges, integrates from one switching instant to the next)");
  }
  s.plant_tolerance = m.number_or("tolerance", 1e-9, 1e-14, 1e-3);
  s.flux_map_file = resolve(base_dir, m.text_or("flux_map", ""));
  s.r_fe_Ohm = m.number_or("r_fe_Ohm", 0.0, 0.0, 1e9);
  if (auto mech = m.optional_map("mechanics")) {
    s.mechanics.dynamometer = mech->choice_or("mode", "dynamometer", {"dynamometer", "inertia"}) == "dynamometer";
    s.mechanics.inertia_kgm2 = mech->number_or("inertia_kgm2", 0.01, 1e-7, 1e4);
    s.mechanics.friction_Nms = mech->number_or("friction_Nms", 0.0, 0.0, 1e4);
    mech->finish();
  }
  m.finish();
}

void parse_control(io::YamlMap m, Scenario& s) {
  s.control.speed_control = m.choice_or("mode", "torque", {"torque", "speed"}) == "speed";
  s.control.current_bandwidth_Hz = m.number_or("current_bandwidth_Hz", 400.0, 1.0, 1e4);
  s.control.speed_bandwidth_Hz = m.number_or("speed_bandwidth_Hz", 5.0, 0.01, 1e3);
  s.control.max_current_A = m.number_or("max_current_A", 0.0, 0.0, 1e5);
  s.control.voltage_margin = m.number_or("voltage_margin", 0.95, 0.5, 1.0);
  s.control.field_weakening = m.boolean_or("field_weakening", true);
  m.finish();
}

core::Vec3 vec3(io::YamlMap& m, const std::string& key, double lo, double hi) {
  if (!m.has(key)) {
    (void)m.text_or(key, "");
    return core::Vec3::Zero();
  }
  const auto v = m.numbers(key, 3, lo, hi);
  return {v[0], v[1], v[2]};
}

void parse_sensors(io::YamlMap m, Scenario& s) {
  auto& c = s.sensors;
  c.current_noise_A = m.number_or("current_noise_A", 0.0, 0.0, 1e3);
  c.current_lsb_A = m.number_or("current_lsb_A", 0.0, 0.0, 1e3);
  c.current_offset_A = vec3(m, "current_offset_A", -1e3, 1e3);
  c.current_gain_error = vec3(m, "current_gain_error", -0.5, 0.5);
  c.encoder_counts = m.number_or("encoder_counts", 0.0, 0.0, 1e9);
  c.theta_offset_rad = m.number_or("theta_offset_rad", 0.0, -3.2, 3.2);
  if (std::optional<io::YamlMap> hall = m.optional_map("hall")) {
    if (c.encoder_counts > 0.0) hall->fail("", "Hall sensors or an encoder (encoder_counts), not both");
    c.hall.enabled = true;
    c.hall.interp_erpm = hall->number_or("interp_erpm", c.hall.interp_erpm, 0.0, 1e6);
    c.hall.observer_erpm = hall->number_or("observer_erpm", c.hall.observer_erpm, 0.0, 1e7);
    hall->finish();
  }
  c.speed_window = static_cast<int>(m.integer_or("speed_window", 8, 1, 10000));
  c.u_dc_noise_V = m.number_or("u_dc_noise_V", 0.0, 0.0, 1e3);
  c.u_dc_lsb_V = m.number_or("u_dc_lsb_V", 0.0, 0.0, 1e3);
  m.finish();
}

Quantity parse_quantity(io::YamlMap& m, const std::string& key) {
  const std::string name = m.choice(key, {"psi_m_Wb", "r_s_Ohm", "l_d_H", "l_q_H", "speed_rpm", "torque_Nm", "u_dc_V",
                                          "t_winding_C", "t_magnet_C", "load_torque_Nm"});
  for (std::size_t q = 0; q < kQuantityNames.size(); ++q) {
    if (name == kQuantityNames[q]) return static_cast<Quantity>(q);
  }
  m.fail(key, "unknown quantity");
}

void parse_events(std::vector<io::YamlMap> events, Scenario& s) {
  std::array<double, static_cast<int>(Quantity::kCount)> last_t;
  last_t.fill(-kHuge);
  for (io::YamlMap& e : events) {
    SignalEvent ev;
    ev.t_s = e.number("t_s", -kHuge, kHuge);
    const Quantity q = parse_quantity(e, "quantity");
    const std::string kind = e.choice("kind", {"step", "ramp", "thermal"});
    ev.kind = kind == "step" ? EventKind::kStep : (kind == "ramp" ? EventKind::kRamp : EventKind::kThermal);
    const bool has_value = e.has("value"), has_scale = e.has("scale");
    if (has_value == has_scale) e.fail("value", "give exactly one of value and scale");
    ev.target = has_value ? e.number("value", -kHuge, kHuge) : e.number("scale", -1e3, 1e3) * s.signal(q).initial();
    if (ev.kind == EventKind::kRamp) ev.duration_s = e.number("duration_s", 0.0, kHuge);
    if (ev.kind == EventKind::kThermal) ev.duration_s = e.number("tau_s", 1e-6, kHuge);
    e.finish();
    auto& last = last_t[static_cast<std::size_t>(q)];
    if (ev.t_s < last) e.fail("t_s", "events of one quantity must be in time order");
    last = ev.t_s;
    if ((q == Quantity::kTWinding || q == Quantity::kTMagnet) && s.thermal_plant.enabled) {
      e.fail("quantity", "the temperatures are thermal_plant's state, driven by the losses; not events");
    }
    if (q == Quantity::kLoadTorque) {
      if (s.mechanics.dynamometer)
        e.fail("quantity", "load_torque_Nm needs plant.mechanics.mode: inertia (a dynamometer imposes the speed)");
      s.separate_load = true;
    }
    s.signal(q).add(ev);
  }
}

ControlOverride parse_control_override(io::YamlMap& e, const Scenario& s) {
  if (!e.has("control")) {
    (void)e.text_or("control", "");
    return ControlOverride::kScenario;
  }
  const bool speed = e.choice("control", {"torque", "speed"}) == "speed";
  if (speed && s.mechanics.dynamometer) e.fail("control", "speed control needs plant.mechanics.mode: inertia");
  return speed ? ControlOverride::kSpeed : ControlOverride::kTorque;
}

OffVoltageReport parse_report(io::YamlMap& e) {
  return e.choice_or("report", "back_emf", {"back_emf", "zero"}) == "zero" ? OffVoltageReport::kZero
                                                                           : OffVoltageReport::kBackEmf;
}

/// `regimes:` (docs/scenarios.md, "Regimes"): what the controller does with the bridge from each t_s on.
void parse_regimes(std::vector<io::YamlMap> events, Scenario& s) {
  double last_t = -kHuge;
  for (io::YamlMap& e : events) {
    RegimeEvent r;
    r.t_s = e.number("t_s", -kHuge, kHuge);
    if (!(r.t_s > last_t)) e.fail("t_s", "regime events must be in strictly increasing time");
    last_t = r.t_s;
    const std::string regime = e.choice("regime", {"closed_loop", "open_loop", "bridge_off"});
    r.regime = regime == "closed_loop" ? DriveRegime::kClosedLoop
                                       : (regime == "open_loop" ? DriveRegime::kOpenLoop : DriveRegime::kBridgeOff);
    r.then =
        r.regime == DriveRegime::kOpenLoop
            ? (e.choice_or("then", "closed_loop", {"closed_loop", "bridge_off"}) == "bridge_off" ? DriveRegime::kBridgeOff
                                                                                                 : DriveRegime::kClosedLoop)
            : r.regime;
    if (r.regime == DriveRegime::kOpenLoop) {
      r.current_A = e.number("current_A", 1e-3, 1e5);
      r.speed_rpm = e.number("speed_rpm", -1e6, 1e6);
      if (r.speed_rpm == 0.0) e.fail("speed_rpm", "must not be 0 (its sign is the direction)");
      r.lock_s = e.number_or("lock_s", 0.0, 0.0, 1e4);
      r.ramp_s = e.number("ramp_s", 1e-3, 1e4);
      r.hold_s = e.number_or("hold_s", 0.05, 0.0, 1e4);
    }
    if (r.then == DriveRegime::kClosedLoop) r.control = parse_control_override(e, s);
    if (r.then == DriveRegime::kBridgeOff) r.report = parse_report(e);
    e.finish();
    s.regimes.push_back(r);
  }
}

void parse_thermal_plant(io::YamlMap m, Scenario& s) {
  // The machine's own heat capacities, conductances and losses: required, as no default fits every machine.
  ThermalPlantConfig& t = s.thermal_plant;
  t.enabled = true;
  t.coolant_C = m.number("coolant_C", -273.0, 1000.0);
  for (auto [key, v] : {std::pair{"winding_J_K", &t.winding_J_K},
                        {"iron_J_K", &t.iron_J_K},
                        {"magnet_J_K", &t.magnet_J_K},
                        {"winding_iron_W_K", &t.winding_iron_W_K},
                        {"iron_coolant_W_K", &t.iron_coolant_W_K},
                        {"gap_W_K", &t.gap_W_K}}) {
    *v = m.number(key, 1e-9, 1e12);
  }
  for (auto [key, v] : {std::pair{"magnet_coolant_W_K", &t.magnet_coolant_W_K},
                        {"hysteresis_W", &t.hysteresis_W},
                        {"eddy_W", &t.eddy_W},
                        {"magnet_eddy_W", &t.magnet_eddy_W}}) {
    *v = m.number(key, 0.0, 1e12);
  }
  t.gap_speed_gain = m.number_or("gap_speed_gain", t.gap_speed_gain, 0.0, 1e3);
  t.steinmetz_beta = m.number_or("steinmetz_beta", t.steinmetz_beta, 1.0, 3.0);
  if (auto start = m.optional_map("start_C")) {
    const std::array<const char*, 3> keys = {"winding", "iron", "magnet"};
    for (std::size_t n = 0; n < keys.size(); ++n) t.start_C[n] = start->number_or(keys[n], t.coolant_C, -273.0, 1000.0);
    start->finish();
  }
  m.finish();
}

void parse_vesc(io::YamlMap m, Scenario& s) {
  VescConfig& v = s.vesc;
  v.wheel_diameter_m = m.number_or("wheel_diameter_m", v.wheel_diameter_m, 1e-3, 100.0);
  v.gear_ratio = m.number_or("gear_ratio", v.gear_ratio, 1e-3, 1e4);
  v.battery_cells = static_cast<int>(m.integer_or("battery_cells", v.battery_cells, 1, 255));
  v.battery_Ah = m.number_or("battery_Ah", v.battery_Ah, 1e-3, 1e6);
  m.finish();
}

void set_initial_signals(Scenario& s, std::optional<io::YamlMap> init) {
  const core::MachineSi& m = s.machine.machine;
  auto value = [&](const char* key, double fallback, double lo, double hi) {
    return init ? init->number_or(key, fallback, lo, hi) : fallback;
  };
  s.signal(Quantity::kPsiM) = Signal(value("psi_m_Wb", m.psi_m_Wb, 1e-6, 100.0));
  s.signal(Quantity::kRs) = Signal(value("r_s_Ohm", m.r_s_Ohm, 1e-6, 1e4));
  s.signal(Quantity::kLd) = Signal(value("l_d_H", m.l_d_H, 1e-8, 100.0));
  s.signal(Quantity::kLq) = Signal(value("l_q_H", m.l_q_H, 1e-8, 100.0));
  s.signal(Quantity::kSpeed) = Signal(value("speed_rpm", 0.0, -1e6, 1e6));
  s.signal(Quantity::kTorque) = Signal(value("torque_Nm", 0.0, -1e6, 1e6));
  s.signal(Quantity::kUdc) = Signal(value("u_dc_V", 220.0, 1.0, 1e5));
  s.signal(Quantity::kTWinding) = Signal(value("t_winding_C", s.thermal.r_s.reference_C, -273.0, 1000.0));
  s.signal(Quantity::kTMagnet) = Signal(value("t_magnet_C", s.thermal.psi_m.reference_C, -273.0, 1000.0));
  s.signal(Quantity::kLoadTorque) = Signal(value("load_torque_Nm", 0.0, -1e6, 1e6));
  if (s.thermal_plant.enabled && init) {
    for (const char* key : {"t_winding_C", "t_magnet_C"}) {
      if (init->has(key)) init->fail(key, "with thermal_plant the temperatures start at thermal_plant.start_C");
    }
  }
  if (s.thermal_plant.enabled) {
    // The signals stand still at the plant's start; the simulator reads the plant's state instead.
    s.signal(Quantity::kTWinding) = Signal(s.thermal_plant.start_temperature_C(0));
    s.signal(Quantity::kTMagnet) = Signal(s.thermal_plant.start_temperature_C(2));
  }
  s.separate_load = init && init->has("load_torque_Nm");
  if (s.separate_load && s.mechanics.dynamometer) {
    init->fail("load_torque_Nm", "needs plant.mechanics.mode: inertia (a dynamometer imposes the speed)");
  }
  if (init) init->finish();
}

}  // namespace

Scenario paper_scenario() {
  Scenario s;
  s.name = "paper";
  s.source = "<built-in>";
  s.machine = io::builtin_paper_config();
  set_initial_signals(s, std::nullopt);
  return s;
}

Scenario parse_scenario(const std::string& text, const std::string& name, const std::string& base_dir) {
  io::YamlMap root = io::YamlMap::load_string(text, name);
  Scenario s;
  s.source = name;
  s.name = root.text_or("name", fs::path(name).stem().string());
  const std::string machine = root.text_or("machine", "builtin:paper-ipmsm");
  if (machine == "builtin:paper-ipmsm") {
    s.machine = io::builtin_paper_config();
  } else {
    s.machine = io::load_machine_config(resolve(base_dir, machine));
  }
  s.duration_s = root.number("duration_s", 1e-3, 1e7);
  s.warmup_s = root.number_or("warmup_s", 0.2, 0.0, 1e4);
  s.sample_period_s = root.number_or("sample_period_s", 125e-6, 1e-6, 1.0);
  s.seed = static_cast<std::uint64_t>(root.integer_or("seed", 1, 0, 1L << 62));
  if (auto m = root.optional_map("inverter")) parse_inverter(*m, s);
  s.plant_step_s = s.inverter.model == InverterModel::kAveraged ? s.sample_period_s : 1e-6;
  s.integrator = s.inverter.model == InverterModel::kAveraged ? PlantIntegrator::kFixedStep : PlantIntegrator::kEdges;
  if (auto m = root.optional_map("plant")) parse_plant(*m, s, base_dir);
  const double steps = s.sample_period_s / s.plant_step_s;
  if (std::abs(steps - std::round(steps)) > 1e-6) root.fail("plant", "step_s must divide sample_period_s");
  if (std::abs(s.sample_period_s * s.inverter.switching_frequency_Hz - 0.5) > 1e-9) {
    root.fail("sample_period_s", "must be half the switching period (PWM double update)");
  }
  if (auto m = root.optional_map("control")) parse_control(*m, s);
  s.control.period_s = s.sample_period_s;
  s.control.inertia_kgm2 = s.mechanics.inertia_kgm2;
  if (s.control.speed_control && s.mechanics.dynamometer) {
    root.fail("control", "speed control needs plant.mechanics.mode: inertia (a dynamometer imposes the speed)");
  }
  if (auto m = root.optional_map("sensors")) parse_sensors(*m, s);
  if (auto m = root.optional_map("thermal")) {
    core::ThermalModel& t = s.thermal;
    t.r_s.reference_C = t.psi_m.reference_C = m->number_or("reference_C", t.r_s.reference_C, -273.0, 1000.0);
    t.r_s.coeff_per_K = m->number_or("r_s_coeff_per_K", t.r_s.coeff_per_K, -1.0, 1.0);
    t.psi_m.coeff_per_K = m->number_or("psi_m_coeff_per_K", t.psi_m.coeff_per_K, -1.0, 1.0);
    m->finish();
  }
  if (auto m = root.optional_map("thermal_plant")) parse_thermal_plant(*m, s);
  set_initial_signals(s, root.optional_map("initial"));
  if (root.has("events")) {
    parse_events(root.maps("events"), s);
  } else {
    (void)root.optional_map("events");
  }
  if (root.has("regimes")) {
    parse_regimes(root.maps("regimes"), s);
  } else {
    (void)root.optional_map("regimes");
  }
  if (auto m = root.optional_map("vesc")) parse_vesc(*m, s);
  if (auto m = root.optional_map("log")) {
    s.log.dq_columns = m->boolean_or("dq_columns", false);
    s.log.temperatures = m->boolean_or("temperatures", false);
    s.log.torque_cmd = m->boolean_or("torque_cmd", false);
    m->finish();
  }
  root.finish();
  return s;
}

Scenario load_scenario(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw io::ConfigError(path, 0, 0, "", "is a directory, not a file");
  std::ifstream in(path);
  if (!in) throw io::ConfigError(path, 0, 0, "", "cannot open file");
  std::stringstream text;
  text << in.rdbuf();
  return parse_scenario(text.str(), path, fs::path(path).parent_path().string());
}

}  // namespace rpem::sim
