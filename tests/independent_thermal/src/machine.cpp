#include "indep_thermal/machine.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "indep_thermal/errors.hpp"
#include "indep_thermal/pi.hpp"

namespace indep_thermal {

namespace {

[[noreturn]] void fail(const std::string& path, const YAML::Node& node, const std::string& key, const std::string& why) {
  const int line = node.IsDefined() ? node.Mark().line + 1 : 0;
  throw ConfigError(path + ":" + std::to_string(line) + ": " + key + ": " + why);
}

double number(const std::string& path, const YAML::Node& parent, const char* name, const std::string& key, double lo,
              double hi, bool required = true) {
  const YAML::Node node = parent[name];
  if (!node) {
    if (required) fail(path, parent, key, "missing");
    return 0.0;
  }
  double value = 0.0;
  try {
    value = node.as<double>();
  } catch (const YAML::Exception&) {
    fail(path, node, key, "not a number");
  }
  if (!std::isfinite(value) || value < lo || value > hi) {
    fail(path, node, key, "outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return value;
}

}  // namespace

double Machine::peak_current_A() const { return std::sqrt(2.0) * current_rms_A; }
double Machine::peak_voltage_V() const { return std::sqrt(2.0 / 3.0) * voltage_ll_rms_V; }
double Machine::omega_mech_rated_rad_s() const { return 2.0 * kPi * speed_rpm / 60.0; }
double Machine::omega_el_rated_rad_s() const { return pole_pairs * omega_mech_rated_rad_s(); }

double Machine::rated_torque_Nm() const {
  if (torque_Nm > 0.0) return torque_Nm;
  if (power_W > 0.0) return power_W / omega_mech_rated_rad_s();
  return 0.85 * std::sqrt(3.0) * voltage_ll_rms_V * current_rms_A / omega_mech_rated_rad_s();
}

double Machine::rated_power_W() const { return rated_torque_Nm() * omega_mech_rated_rad_s(); }

Machine read_machine(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw ConfigError(path + ": cannot be read");
  } catch (const YAML::Exception& e) {
    throw ConfigError(path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  const YAML::Node machine = root["machine"];
  if (!machine || !machine.IsMap()) fail(path, root, "machine", "missing or not a map");
  const YAML::Node rated = machine["rated"];
  if (!rated || !rated.IsMap()) fail(path, machine, "machine.rated", "missing or not a map");

  Machine m;
  m.source = path;
  m.voltage_ll_rms_V = number(path, rated, "voltage_ll_rms_V", "machine.rated.voltage_ll_rms_V", 1, 1e5);
  m.current_rms_A = number(path, rated, "current_rms_A", "machine.rated.current_rms_A", 1e-3, 1e5);
  m.speed_rpm = number(path, rated, "speed_rpm", "machine.rated.speed_rpm", 1, 1e6);
  const double p = number(path, rated, "pole_pairs", "machine.rated.pole_pairs", 1, 100);
  if (p != std::floor(p)) fail(path, rated["pole_pairs"], "machine.rated.pole_pairs", "not an integer");
  m.pole_pairs = static_cast<int>(p);
  m.power_W = number(path, rated, "power_W", "machine.rated.power_W", 0, 1e9, false);
  m.torque_Nm = number(path, rated, "torque_Nm", "machine.rated.torque_Nm", 0, 1e7, false);
  m.r_s_Ohm = number(path, machine, "r_s_Ohm", "machine.r_s_Ohm", 1e-6, 1e4);
  m.psi_m_Wb = number(path, machine, "psi_m_Wb", "machine.psi_m_Wb", 1e-6, 100);
  m.l_d_H = number(path, machine, "l_d_H", "machine.l_d_H", 1e-8, 100);
  m.l_q_H = number(path, machine, "l_q_H", "machine.l_q_H", 1e-8, 100);
  return m;
}

}  // namespace indep_thermal
