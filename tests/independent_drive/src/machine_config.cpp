#include "indep_drive/machine_config.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "indep_drive/frames.hpp"

namespace indep {

double MachineConfig::rated_peak_current_A() const { return std::sqrt(2.0) * rated.current_rms_A; }

double MachineConfig::rated_omega_el_rad_s() const { return 2.0 * kPi * rated.speed_rpm / 60.0 * params.pole_pairs; }

double MachineConfig::torque_base_Nm() const { return 1.5 * params.pole_pairs * params.psi_m_Wb * rated_peak_current_A(); }

double MachineConfig::reference_power_W() const {
  return rated.power_W > 0.0 ? rated.power_W : kSqrt3 * rated.voltage_ll_rms_V * rated.current_rms_A;
}

namespace {

[[noreturn]] void fail(const std::string& path, const YAML::Node& node, const std::string& key, const std::string& why) {
  const int line = node.IsDefined() ? node.Mark().line + 1 : 0;
  throw ConfigError(path + ":" + std::to_string(line) + ": " + key + ": " + why);
}

double positive(const std::string& path, const YAML::Node& parent, const char* name, const std::string& key, double lo,
                double hi) {
  const YAML::Node node = parent[name];
  if (!node) fail(path, parent, key, "missing");
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

MachineConfig read_machine_config(const std::string& path) {
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

  MachineConfig c;
  c.source = path;
  c.rated.voltage_ll_rms_V = positive(path, rated, "voltage_ll_rms_V", "machine.rated.voltage_ll_rms_V", 1, 1e5);
  c.rated.current_rms_A = positive(path, rated, "current_rms_A", "machine.rated.current_rms_A", 1e-3, 1e5);
  c.rated.speed_rpm = positive(path, rated, "speed_rpm", "machine.rated.speed_rpm", 1, 1e6);
  const double p = positive(path, rated, "pole_pairs", "machine.rated.pole_pairs", 1, 100);
  if (p != std::floor(p)) fail(path, rated["pole_pairs"], "machine.rated.pole_pairs", "not an integer");
  c.params.pole_pairs = static_cast<int>(p);
  if (rated["power_W"]) c.rated.power_W = positive(path, rated, "power_W", "machine.rated.power_W", 0, 1e9);
  c.params.r_s_Ohm = positive(path, machine, "r_s_Ohm", "machine.r_s_Ohm", 1e-6, 1e4);
  c.params.psi_m_Wb = positive(path, machine, "psi_m_Wb", "machine.psi_m_Wb", 1e-6, 100);
  c.params.l_d_H = positive(path, machine, "l_d_H", "machine.l_d_H", 1e-8, 100);
  c.params.l_q_H = positive(path, machine, "l_q_H", "machine.l_q_H", 1e-8, 100);
  return c;
}

}  // namespace indep
