#include "rpem/daemon/daemon_config.hpp"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace rpem::daemon {
namespace {

namespace fs = std::filesystem;

ThreadPolicy parse_thread(io::YamlMap m, ThreadPolicy p) {
  const std::string policy = m.choice_or("policy", p.fifo ? "fifo" : "other", {"fifo", "other"});
  p.fifo = policy == "fifo";
  p.priority = static_cast<int>(m.integer_or("priority", p.priority, p.fifo ? 1 : 0, p.fifo ? 99 : 0));
  p.cpu = static_cast<int>(m.integer_or("cpu", p.cpu, -1, 1023));
  m.finish();
  return p;
}

void parse_daemon(io::YamlMap d, DaemonConfig& c, const std::string& base_dir) {
  if (auto s = d.optional_map("source")) {
    c.source = s->choice("type", {"sim", "can"}) == "can" ? SourceType::kCan : SourceType::kSim;
    if (auto can = s->optional_map("can")) {
      c.can_interface = can->text("interface");
      if (c.can_interface.empty() || c.can_interface.size() > 15) can->fail("interface", "not an interface name");
      can->finish();
    }
    if (auto sim = s->optional_map("sim")) {
      c.sim_scenario = sim->text_or("scenario", c.sim_scenario);
      if (c.sim_scenario.rfind("builtin:", 0) != 0 && fs::path(c.sim_scenario).is_relative()) {
        c.sim_scenario = (fs::path(base_dir) / c.sim_scenario).lexically_normal().string();
      }
      c.sim_loop = sim->boolean_or("loop", true);
      sim->finish();
    }
    s->finish();
  }
  if (auto l = d.optional_map("loop")) {
    c.loop_period_s = l->number_or("period_s", c.loop_period_s, 10e-6, 0.1);
    if (l->has("wake_ahead_s") && l->text_or("wake_ahead_s", "") == "auto") {
      c.loop_wake_ahead_auto = true;
    } else {
      c.loop_wake_ahead_s = l->number_or("wake_ahead_s", c.loop_wake_ahead_s, 0.0, 0.5 * c.loop_period_s);
    }
    const std::string rt = l->choice_or("realtime", "preferred", {"required", "preferred", "off"});
    c.realtime = rt == "required" ? RealtimeMode::kRequired : rt == "off" ? RealtimeMode::kOff : RealtimeMode::kPreferred;
    c.lock_memory = l->boolean_or("lock_memory", true);
    c.cpu_dma_latency_us = static_cast<int>(l->integer_or("cpu_dma_latency_us", 0, -1, 100000));
    if (auto t = l->optional_map("thread")) c.loop_thread = parse_thread(*t, c.loop_thread);
    l->finish();
  }
  if (auto t = d.optional_map("receive_thread")) c.receive_thread = parse_thread(*t, c.receive_thread);
  if (auto t = d.optional_map("publish_thread")) c.publish_thread = parse_thread(*t, c.publish_thread);
  c.stale_timeout_s = d.number_or("stale_timeout_s", c.stale_timeout_s, 1e-3, 60.0);
  if (auto l = d.optional_map("lcm")) {
    c.lcm_url = l->text_or("url", "");
    c.channel_prefix = l->text_or("channel_prefix", "");
    c.estimate_rate_Hz = l->number_or("estimate_rate_Hz", c.estimate_rate_Hz, 0.1, 1000.0);
    c.measurement_rate_Hz = l->number_or("measurement_rate_Hz", c.measurement_rate_Hz, 0.0, 8000.0);
    c.diagnostics_rate_Hz = l->number_or("diagnostics_rate_Hz", c.diagnostics_rate_Hz, 0.1, 10.0);
    l->finish();
  }
  if (auto cmd = d.optional_map("commands")) {
    c.commands_enabled = cmd->boolean_or("enabled", false);
    cmd->finish();
  }
  if (auto t = d.optional_map("temperature")) {
    core::ThermalModel& m = c.temperature;
    m.r_s.reference_C = m.psi_m.reference_C = t->number_or("reference_C", m.r_s.reference_C, -273.0, 500.0);
    m.r_s.value_ref = t->number_or("r_s_ref_Ohm", m.r_s.value_ref, 1e-6, 1e4);
    m.psi_m.value_ref = t->number_or("psi_m_ref_Wb", m.psi_m.value_ref, 1e-6, 100.0);
    m.r_s.coeff_per_K = t->number_or("r_s_coeff_per_K", m.r_s.coeff_per_K, 1e-5, 0.1);
    m.psi_m.coeff_per_K = t->number_or("psi_m_coeff_per_K", m.psi_m.coeff_per_K, -0.1, -1e-6);
    t->finish();
  }
  if (auto v = d.optional_map("validity")) {
    c.validity.r_s_after_s = v->number_or("r_s_after_s", c.validity.r_s_after_s, 0.0, 3600.0);
    c.validity.psi_m_after_s = v->number_or("psi_m_after_s", c.validity.psi_m_after_s, 0.0, 3600.0);
    c.validity.convergence_window_s = v->number_or("convergence_window_s", c.validity.convergence_window_s, 0.1, 600.0);
    c.validity.convergence_band = v->number_or("convergence_band", c.validity.convergence_band, 1e-6, 0.5);
    v->finish();
  }
  if (auto s = d.optional_map("state")) {
    c.state_file = s->text_or("file", "");
    c.state_write_interval_s = s->number_or("write_interval_s", c.state_write_interval_s, 0.1, 86400.0);
    c.state_max_age_s = s->number_or("max_age_s", c.state_max_age_s, 0.0, 1e8);
    s->finish();
  }
  c.status_interval_s = d.number_or("status_interval_s", c.status_interval_s, 0.0, 3600.0);
  d.finish();
}

/// The temperature model's defaults from the drifts a diagnosis found (docs/model-extensions.md); the
/// daemon section's own `temperature` keys, parsed afterwards, override them.
void temperature_from_drifts(const std::string& name, DaemonConfig& c) {
  const io::ParameterDrift &r = c.machine.rs_drift, &p = c.machine.psim_drift;
  if (r.law) {
    if (r.law->coeff_per_K <= 0.0) {
      throw io::ConfigError(name, 0, 0, "model_extensions.rs_drift.coeff_per_K",
                            "a winding temperature needs a resistance that rises with it (coefficient > 0)");
    }
    c.temperature.r_s = *r.law;
  }
  if (p.law) {
    if (p.law->coeff_per_K >= 0.0) {
      throw io::ConfigError(name, 0, 0, "model_extensions.psim_drift.coeff_per_K",
                            "a magnet temperature needs a flux linkage that falls with it (coefficient < 0)");
    }
    c.temperature.psi_m = *p.law;
  }
}

void fill_defaults(DaemonConfig& c) {
  if (c.temperature.r_s.value_ref <= 0.0) c.temperature.r_s.value_ref = c.machine.machine.r_s_Ohm;
  if (c.temperature.psi_m.value_ref <= 0.0) c.temperature.psi_m.value_ref = c.machine.machine.psi_m_Wb;
}

DaemonConfig parse(io::YamlMap& root, const std::string& name, const std::string& base_dir) {
  DaemonConfig c;
  c.source_file = name;
  std::optional<io::YamlMap> d = root.optional_map("daemon");
  std::string machine_file;
  if (d && d->has("machine_config")) machine_file = d->text("machine_config");
  if (!machine_file.empty()) {
    if (root.has("machine")) root.fail("machine", "give the machine inline or daemon.machine_config, not both");
    c.machine = machine_file == "builtin:paper-ipmsm"
                    ? io::builtin_paper_config()
                    : io::load_machine_config((fs::path(base_dir) / machine_file).lexically_normal().string());
  } else if (root.has("machine")) {
    c.machine = io::parse_machine_config(root);
  } else {
    c.machine = io::builtin_paper_config();
  }
  temperature_from_drifts(name, c);
  if (d) parse_daemon(*d, c, base_dir);
  root.finish();
  fill_defaults(c);
  return c;
}

}  // namespace

DaemonConfig load_daemon_config(const std::string& path) {
  io::YamlMap root = io::YamlMap::load_file(path);
  return parse(root, path, fs::path(path).parent_path().string());
}

DaemonConfig builtin_daemon_config() {
  io::YamlMap root = io::YamlMap::load_string("daemon: {}\n", "<built-in>");
  return parse(root, "<built-in>", "");
}

std::string resolve_state_file(const DaemonConfig& c) {
  if (!c.state_file.empty()) return c.state_file;
  if (const char* dir = std::getenv("STATE_DIRECTORY")) return std::string(dir) + "/estimates.json";
  if (const char* xdg = std::getenv("XDG_STATE_HOME")) return std::string(xdg) + "/rpemd/estimates.json";
  if (const char* home = std::getenv("HOME")) return std::string(home) + "/.local/state/rpemd/estimates.json";
  return "rpemd-estimates.json";
}

}  // namespace rpem::daemon
