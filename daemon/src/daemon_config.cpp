#include "rpem/daemon/daemon_config.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <variant>

#include "rpem/core/reported_speed.hpp"
#include "rpem/io/averaged_log.hpp"
#include "rpem/io/thermal_config.hpp"

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

void parse_loop(io::YamlMap& l, LoopConfig& c) {
  c.period_s = l.number_or("period_s", c.period_s, 10e-6, 0.1);
  if (l.has("wake_ahead_s") && l.text_or("wake_ahead_s", "") == "auto") {
    c.wake_ahead_auto = true;
  } else {
    c.wake_ahead_s = l.number_or("wake_ahead_s", c.wake_ahead_s, 0.0, 0.5 * c.period_s);
  }
  const std::string rt = l.choice_or("realtime", "preferred", {"required", "preferred", "off"});
  c.realtime = rt == "required" ? RealtimeMode::kRequired : rt == "off" ? RealtimeMode::kOff : RealtimeMode::kPreferred;
  c.lock_memory = l.boolean_or("lock_memory", c.lock_memory);
  c.cpu_dma_latency_us = static_cast<int>(l.integer_or("cpu_dma_latency_us", c.cpu_dma_latency_us, -1, 100000));
  if (auto t = l.optional_map("thread")) c.thread = parse_thread(*t, c.thread);
  l.finish();
}

void parse_lcm(io::YamlMap& l, LcmConfig& c) {
  c.url = l.text_or("url", c.url);
  c.channel_prefix = l.text_or("channel_prefix", c.channel_prefix);
  c.estimate_rate_Hz = l.number_or("estimate_rate_Hz", c.estimate_rate_Hz, 0.1, 1000.0);
  c.measurement_rate_Hz = l.number_or("measurement_rate_Hz", c.measurement_rate_Hz, 0.0, 8000.0);
  c.diagnostics_rate_Hz = l.number_or("diagnostics_rate_Hz", c.diagnostics_rate_Hz, 0.1, 10.0);
  l.finish();
}

void parse_temperature(io::YamlMap& t, TemperatureModel& m) {
  m.r_s.reference_C = m.psi_m.reference_C = t.number_or("reference_C", m.r_s.reference_C, -273.0, 500.0);
  m.r_s.value_ref = t.number_or("r_s_ref_Ohm", m.r_s.value_ref, 1e-6, 1e4);
  m.psi_m.value_ref = t.number_or("psi_m_ref_Wb", m.psi_m.value_ref, 1e-6, 100.0);
  m.r_s.coeff_per_K = t.number_or("r_s_coeff_per_K", m.r_s.coeff_per_K, 1e-5, 0.1);
  m.psi_m.coeff_per_K = t.number_or("psi_m_coeff_per_K", m.psi_m.coeff_per_K, -0.1, -1e-6);
  t.finish();
}

void parse_validity(io::YamlMap& v, ValidityConfig& c) {
  c.r_s_after_s = v.number_or("r_s_after_s", c.r_s_after_s, 0.0, 3600.0);
  c.psi_m_after_s = v.number_or("psi_m_after_s", c.psi_m_after_s, 0.0, 3600.0);
  c.max_hold_s = v.number_or("max_hold_s", c.max_hold_s, 0.0, 1e6);
  c.convergence_window_s = v.number_or("convergence_window_s", c.convergence_window_s, 0.1, 600.0);
  c.convergence_band = v.number_or("convergence_band", c.convergence_band, 1e-6, 0.5);
  v.finish();
}

void parse_state(io::YamlMap& s, StateConfig& c) {
  c.file = s.text_or("file", c.file);
  c.write_interval_s = s.number_or("write_interval_s", c.write_interval_s, 0.1, 86400.0);
  c.max_age_s = s.number_or("max_age_s", c.max_age_s, 0.0, 1e8);
  s.finish();
}

/// A time for a message, to 3 significant digits (2·0.1 + 0.02 reads 0.22).
std::string seconds_text(double s) {
  std::array<char, 32> buf{};
  const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), s, std::chars_format::general, 3);
  return ec == std::errc() ? std::string(buf.data(), end) : std::string("?");
}

/// `stale_timeout_s`, after the source: where the source spaces its samples (a poller), the default outlasts one lost
/// reply, and a timeout within the normal spacing is refused — the loop would go stale, and start over, between two
/// samples (docs/rpemd.md, "Configuration").
void parse_stale_timeout(io::YamlMap& d, FixedConfig& f) {
  const SampleSpacing spacing = SourceCatalogue::sample_spacing(f.source);
  const double default_s = std::max(f.loop.stale_timeout_s, spacing.one_lost_s);
  f.loop.stale_timeout_s = d.number_or("stale_timeout_s", default_s, 1e-3, 60.0);
  if (f.loop.stale_timeout_s <= spacing.normal_s) {
    d.fail("stale_timeout_s", seconds_text(f.loop.stale_timeout_s) + " s is within the " + seconds_text(spacing.normal_s) +
                                  " s the " + SourceCatalogue::type(f.source) +
                                  " source's samples may come apart (one poll period and reply_timeout_s): rpemd would "
                                  "go stale, and start over, between two of them; leave it out (then " +
                                  seconds_text(spacing.one_lost_s) +
                                  " s, two periods and the timeout: one lost reply) or give more");
  }
}

void parse_daemon(io::YamlMap d, DaemonConfig& c, const std::string& base_dir) {
  FixedConfig& f = c.fixed;
  if (auto s = d.optional_map("source")) f.source = SourceCatalogue::parse(*s, base_dir);
  if (auto l = d.optional_map("loop")) parse_loop(*l, f.loop);
  if (auto t = d.optional_map("receive_thread")) f.receive_thread = parse_thread(*t, f.receive_thread);
  if (auto t = d.optional_map("publish_thread")) f.publish_thread = parse_thread(*t, f.publish_thread);
  parse_stale_timeout(d, f);
  if (auto l = d.optional_map("lcm")) parse_lcm(*l, f.lcm);
  if (auto cmd = d.optional_map("commands")) {
    c.live.commands_enabled = cmd->boolean_or("enabled", c.live.commands_enabled);
    const std::string mode = cmd->choice_or("authentication", "hmac-sha256", {"hmac-sha256", "none"});
    c.live.command_authentication = mode == "none" ? CommandAuthentication::kNone : CommandAuthentication::kRequired;
    const std::string url = effective_lcm_url(f.lcm.url);
    if (c.live.command_authentication == CommandAuthentication::kNone && !lcm_is_local(url)) {
      cmd->fail("authentication", "`none` is for commands that cannot leave this host, but LCM's URL " + url +
                                      " reaches the network (ttl > 0 or not udpm/memq); configure a command key instead "
                                      "(docs/rpemd.md, \"Authentication\")");
    }
    cmd->finish();
  }
  if (auto t = d.optional_map("temperature")) parse_temperature(*t, c.live.temperature);
  if (auto v = d.optional_map("validity")) parse_validity(*v, c.live.validity);
  if (auto s = d.optional_map("state")) parse_state(*s, f.state);
  f.status_interval_s = d.number_or("status_interval_s", f.status_interval_s, 0.0, 3600.0);
  d.finish();
}

/// The temperature model's defaults from the drifts a diagnosis found (docs/model-extensions.md); the
/// daemon section's own `temperature` keys, parsed afterwards, override them.
void temperature_from_drifts(const std::string& name, const io::MachineConfig& machine, TemperatureModel& t) {
  const io::ParameterDrift &r = machine.rs_drift, &p = machine.psim_drift;
  if (r.law) {
    if (r.law->coeff_per_K <= 0.0) {
      throw io::ConfigError(name, 0, 0, "model_extensions.rs_drift.coeff_per_K",
                            "a winding temperature needs a resistance that rises with it (coefficient > 0)");
    }
    t.r_s = *r.law;
  }
  if (p.law) {
    if (p.law->coeff_per_K >= 0.0) {
      throw io::ConfigError(name, 0, 0, "model_extensions.psim_drift.coeff_per_K",
                            "a magnet temperature needs a flux linkage that falls with it (coefficient < 0)");
    }
    t.psi_m = *p.law;
  }
}

void fill_defaults(const io::MachineConfig& machine, TemperatureModel& t) {
  if (t.r_s.value_ref <= 0.0) t.r_s.value_ref = machine.machine.r_s_Ohm;
  if (t.psi_m.value_ref <= 0.0) t.psi_m.value_ref = machine.machine.psi_m_Wb;
}

/// The machine's model extensions must be ones the source's samples can be corrected for (averaged
/// samples: no per-phase current errors; a dead time in seconds: the DC link).
void check_source_supports(const DaemonConfig& c) {
  const io::MachineConfig& m = c.live.machine;
  if (const auto* v = std::get_if<VescSource::Options>(&c.fixed.source)) {
    io::check_averaged_supports(m, c.source_file, true, "source vesc, controller " + std::to_string(v->controller_id));
  } else if (const auto* s = std::get_if<SignalMapSource::Options>(&c.fixed.source)) {
    if (s->kind == SampleKind::kAveraged) {
      io::check_averaged_supports(m, c.source_file, s->gives_u_dc, s->map);
    } else {
      io::check_log_supports(m, c.source_file, s->gives_u_dc, s->map);
    }
  }
}

DaemonConfig parse(io::YamlMap& root, const std::string& name, const std::string& base_dir) {
  DaemonConfig c;
  c.source_file = name;
  std::optional<io::YamlMap> d = root.optional_map("daemon");
  std::string machine_file;
  if (d && d->has("machine_config")) machine_file = d->text("machine_config");
  std::string thermal_file;
  if (d && d->has("thermal_config")) thermal_file = d->text("thermal_config");
  io::MachineConfig& machine = c.live.machine;
  if (!machine_file.empty()) {
    if (root.has("machine")) root.fail("machine", "give the machine inline or daemon.machine_config, not both");
    machine = machine_file == "builtin:paper-ipmsm"
                  ? io::builtin_paper_config()
                  : io::load_machine_config((fs::path(base_dir) / machine_file).lexically_normal().string());
  } else if (root.has("machine")) {
    machine = io::parse_machine_config(root);
  } else {
    machine = io::builtin_paper_config();
  }
  temperature_from_drifts(name, machine, c.live.temperature);
  std::optional<io::ThermalConfig> thermal;
  if (!thermal_file.empty()) {
    if (root.has("thermal")) root.fail("thermal", "give the thermal section inline or daemon.thermal_config, not both");
    thermal = io::load_thermal_config((fs::path(base_dir) / thermal_file).lexically_normal().string(), machine);
  } else if (root.has("thermal")) {
    io::YamlMap t = root.map("thermal");
    thermal = io::parse_thermal_config(t, machine);
  }
  if (thermal) {
    c.live.thermal = thermal->fusion;
    c.live.thermal_active = true;
    c.notes = io::assumed_law_notes(*thermal, true);
    if (std::optional<std::string> note = io::process_noise_note(*thermal)) c.notes.push_back(std::move(*note));
  }
  if (d) parse_daemon(*d, c, base_dir);
  root.finish();
  // A Hall drive's staircase angle: the VESC source counts each window's speed from the tachometer (CountDelay).
  if (auto* v = std::get_if<VescSource::Options>(&c.fixed.source)) {
    v->count_horizon_s = machine.estimator.regimes.hall_interpolation_speed_rad_s > 0.0 ? core::kCountRunSideMaxS : 0.0;
  }
  fill_defaults(machine, c.live.temperature);
  check_source_supports(c);
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

std::string resolve_state_file(const StateConfig& c) {
  if (!c.file.empty()) return c.file;
  if (const char* dir = std::getenv("STATE_DIRECTORY")) return std::string(dir) + "/estimates.json";
  if (const char* xdg = std::getenv("XDG_STATE_HOME")) return std::string(xdg) + "/rpemd/estimates.json";
  if (const char* home = std::getenv("HOME")) return std::string(home) + "/.local/state/rpemd/estimates.json";
  return "rpemd-estimates.json";
}

std::string effective_lcm_url(const std::string& url) {
  if (!url.empty()) return url;
  if (const char* env = std::getenv("LCM_DEFAULT_URL"); env != nullptr && *env != '\0') return env;
  return "udpm://239.255.76.67:7667?ttl=0";
}

bool lcm_is_local(const std::string& url) {
  if (url.rfind("memq://", 0) == 0) return true;
  if (url.rfind("udpm://", 0) != 0) return false;
  const std::size_t query = url.find('?');
  if (query == std::string::npos) return true;  // LCM's udpm ttl defaults to 0
  std::size_t at = query + 1;
  while (at < url.size()) {
    const std::size_t end = std::min(url.find('&', at), url.size());
    const std::string option = url.substr(at, end - at);
    if (option.rfind("ttl=", 0) == 0) return option == "ttl=0";
    at = end + 1;
  }
  return true;
}

const char* fixed_difference(const FixedConfig& a, const FixedConfig& b) {
  if (!(a.source == b.source)) return "source";
  if (!(a.loop == b.loop)) return "loop";
  if (!(a.receive_thread == b.receive_thread) || !(a.publish_thread == b.publish_thread)) return "threads";
  if (!(a.lcm == b.lcm)) return "lcm";
  if (!(a.state == b.state)) return "state";
  if (a.status_interval_s != b.status_interval_s) return "status_interval_s";
  return "";
}

}  // namespace rpem::daemon
