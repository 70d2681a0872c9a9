#include "rpem/daemon/daemon.hpp"

#include <sys/signalfd.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string_view>

#include "rpem/core/clock.hpp"
#include "rpem/daemon/control.hpp"
#include "rpem/daemon/credentials.hpp"
#include "rpem/daemon/realtime.hpp"
#include "rpem/daemon/state_file.hpp"
#include "rpem/daemon/vesc_source.hpp"
#include "rpem/io/exit_codes.hpp"
#include "rpem/io/thermal_config.hpp"

namespace rpem::daemon {
namespace {

const char* realtime_name(RealtimeMode m) {
  return m == RealtimeMode::kRequired ? "required" : m == RealtimeMode::kOff ? "off" : "preferred";
}

/// SIGTERM, SIGINT and SIGHUP blocked in the calling thread (and every thread it starts later), read
/// instead from the returned signalfd.
int block_signals_into_fd() {
  sigset_t signals;
  sigemptyset(&signals);
  for (int s : {SIGTERM, SIGINT, SIGHUP}) sigaddset(&signals, s);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  return signalfd(-1, &signals, SFD_NONBLOCK | SFD_CLOEXEC);
}

/// Locks rpemd's memory where the configuration asks for it with a real-time loop; false when that fails
/// and real time is required (a warning otherwise).
bool lock_memory_if_asked(const LoopConfig& loop, bool realtime, bool required) {
  if (!loop.lock_memory || !realtime) return true;
  const std::string problem = lock_memory();
  if (problem.empty()) return true;
  std::fprintf(stderr, required ? "rpemd: %s\n" : "rpemd: warning: %s; continuing without locked memory\n", problem.c_str());
  return !required;
}

/// The /dev/cpu_dma_latency request where the configuration asks for it with a real-time loop: the file
/// descriptor that holds it, or -1 (with a note when the request failed).
int request_cpu_dma_latency_if_asked(const LoopConfig& loop, bool realtime) {
  if (loop.cpu_dma_latency_us < 0 || !realtime) return -1;
  std::string problem;
  const int fd = request_cpu_dma_latency(loop.cpu_dma_latency_us, problem);
  if (fd < 0) std::fprintf(stderr, "rpemd: note: %s; deep CPU idle states may add wake-up latency\n", problem.c_str());
  return fd;
}

/// The two lines rpemd prints when it starts: what it runs, and how it authenticates.
void print_start(const DaemonConfig& config, const std::string& source_name, const char* source_type,
                 const Control::Commands& commands, const std::string& signing) {
  char wake_ahead[32];
  std::snprintf(wake_ahead, sizeof wake_ahead, config.fixed.loop.wake_ahead_auto ? "auto" : "%.0f µs",
                config.fixed.loop.wake_ahead_s * 1e6);
  std::fprintf(stderr,
               "rpemd: source %s '%s', loop %.0f µs (realtime %s, wake-ahead %s), machine %s, algorithm %s, LCM %s, "
               "channels %sRPEM_*, commands %s, state file %s\n",
               source_type, source_name.c_str(), config.fixed.loop.period_s * 1e6, realtime_name(config.fixed.loop.realtime),
               wake_ahead, config.source_file.c_str(), io::to_string(config.live.machine.estimator.algorithm),
               config.fixed.lcm.url.empty() ? "default" : config.fixed.lcm.url.c_str(),
               config.fixed.lcm.channel_prefix.c_str(), config.live.commands_enabled ? "enabled" : "disabled",
               resolve_state_file(config.fixed.state).c_str());
  std::string ids;
  const auth::Keyring& command_keys = commands.keys.keys;
  for (int k = 0; k < command_keys.size(); ++k) ids += (k > 0 ? ", " : "") + std::to_string(command_keys[k].id());
  std::fprintf(stderr, "rpemd: commands %s; last accepted sequence number %lld (%s); estimates and diagnostics %s\n",
               !config.live.commands_enabled ? "disabled (commands.enabled: false)"
               : config.live.command_authentication == CommandAuthentication::kNone
                   ? "unauthenticated (authentication: none, local only)"
                   : (ids.empty() ? std::string("need a key (none loaded)") : "authenticated with key id " + ids).c_str(),
               static_cast<long long>(commands.last_accepted_seq), commands.sequence_file.c_str(), signing.c_str());
  // A VESC is mostly sensorless, the default frame a position sensor's.
  if (const auto* v = std::get_if<VescSource::Options>(&config.fixed.source)) {
    if (const std::string note = io::unstated_frame_note(config.live.machine); !note.empty())
      std::fprintf(stderr, "rpemd: %s\n", note.c_str());
    if (v->count_horizon_s > 0.0) {
      std::fprintf(stderr,
                   "rpemd: a Hall drive (regimes.angle_source: hall): the polls ask for the tachometer, and each window "
                   "waits %.2f s for its speed to be counted over the reads around it (docs/rpemd.md)\n",
                   v->count_horizon_s);
    }
  }
}

}  // namespace

DaemonConfig load_configuration(const DaemonOptions& o) {
  DaemonConfig c = o.config_path.empty() ? builtin_daemon_config() : load_daemon_config(o.config_path);
  if (!o.can_interface.empty()) c.fixed.source = CanSource::Options{o.can_interface};
  return c;
}

Daemon::Daemon(DaemonOptions options, DaemonConfig config)
    : options_(std::move(options)), config_(std::move(config)), source_(SourceCatalogue::make(config_.fixed.source)) {
  source_name_ = source_->name();
}

Daemon::~Daemon() {
  if (source_thread_.joinable() || loop_thread_.joinable() || publisher_thread_.joinable()) stop_threads();
}

void Daemon::seed_from_state_file() {
  const core::EstimatorSettings& est = config_.live.machine.estimator;
  const std::string path = resolve_state_file(config_.fixed.state);
  const LoadedState loaded = load_state_file(path, config_.fixed.state.max_age_s, est.psi_m_min_Wb, est.psi_m_max_Wb,
                                             est.r_s_min_Ohm, est.r_s_max_Ohm);
  state_file_status_ = loaded.status;
  if (loaded.status != StateFileStatus::kNone) std::fprintf(stderr, "rpemd: %s\n", loaded.message.c_str());
  if (loaded.status != StateFileStatus::kLoaded) return;
  const PersistedEstimates& e = loaded.estimates;
  const std::int64_t now_s = std::time(nullptr);
  auto seed = [&](const std::optional<double>& v, std::int64_t adapted_s) -> std::optional<SeedValue> {
    if (!v) return std::nullopt;
    return SeedValue{*v, static_cast<double>(std::max<std::int64_t>(0, now_s - adapted_s))};
  };
  loop_->seed(seed(e.psi_m_Wb, e.psi_m_adapted_unix_s), seed(e.r_s_Ohm, e.r_s_adapted_unix_s),
              core::now_ns(CLOCK_MONOTONIC));
  resume_thermal(e.thermal, now_s);
}

void Daemon::resume_thermal(const PersistedThermal& saved, std::int64_t now_s) {
  const core::ThermalSnapshot& t = saved.state;
  if (t.nodes == 0 || !config_.live.thermal_active) return;
  const std::int64_t gap_s = std::max<std::int64_t>(0, now_s - saved.at_unix_s);
  if (loop_->resume_thermal(t, static_cast<double>(gap_s))) {
    resumed_thermal_ = saved;
    std::fprintf(stderr,
                 "rpemd: the thermal network resumes from the state file (magnet %.1f C, winding %.1f C %ld s ago; the "
                 "load since unknown: between none and the last)\n",
                 t.t_C[t.magnet], t.t_C[t.winding], static_cast<long>(gap_s));
  } else {
    std::fprintf(stderr,
                 "rpemd: the state file's thermal state (%d nodes, winding %d, magnet %d) is not the configured "
                 "network's: it starts from the coolant\n",
                 t.nodes, t.winding, t.magnet);
  }
}

void Daemon::say_untested_soak() const {
  // core::start_temperatures_C: without a resumed state, and without a winding sensor whose first reading could show
  // the machine warm, the fusion takes every node at the coolant.
  if (!config_.live.thermal_active || resumed_thermal_.state.nodes > 0 || config_.live.thermal.winding_sensor_sigma_K > 0.0)
    return;
  const std::string note = io::soaked_start_note(
      "no thermal state resumed from the state file, and no winding sensor (thermal.winding_sensor) to test it");
  std::fprintf(stderr, "rpemd: note: %s\n", note.c_str());
}

void Daemon::start_threads() {
  publisher_thread_ = std::thread([this] { publisher_->run(stop_publisher_); });
  loop_thread_ = std::thread([this] { loop_->run(stop_acquisition_); });
}

void Daemon::stop_threads() {
  stop_acquisition_ = true;
  if (source_thread_.joinable()) source_thread_.join();
  if (loop_thread_.joinable()) loop_thread_.join();
  stop_publisher_ = true;
  if (publisher_thread_.joinable()) publisher_thread_.join();
}

int Daemon::run() {
  // Before any thread exists, so that every thread inherits the mask and the signals arrive as data
  // on the control thread only.
  const int signal_fd = block_signals_into_fd();
  const FixedConfig& fixed = config_.fixed;
  // Keys and replay protection before anything runs: a configuration that cannot authenticate its
  // commands, an unusable key file or a lost sequence number is a configuration error (exit 78).
  DaemonKeys keys;
  Control::Commands commands;
  commands.keys.channel = fixed.lcm.channel_prefix + "RPEM_COMMAND";
  commands.sequence_file = command_sequence_file(resolve_state_file(fixed.state));
  try {
    auth::initialise();  // libsodium, once, before any key exists
    CredentialCheck check = check_credentials(config_.live, std::getenv("CREDENTIALS_DIRECTORY"));
    if (!check.problem.empty()) throw std::runtime_error(check.problem);
    keys = std::move(check.keys);
    commands.keys.keys = std::move(keys.command);  // the control thread's command gate holds them
    commands.last_accepted_seq = load_command_sequence(commands.sequence_file);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rpemd: configuration error: %s\n", e.what());
    if (signal_fd >= 0) ::close(signal_fd);
    return io::kExitConfig;
  }
  const bool realtime = fixed.loop.realtime != RealtimeMode::kOff;
  const bool required = fixed.loop.realtime == RealtimeMode::kRequired;
  if (!lock_memory_if_asked(fixed.loop, realtime, required)) return io::kExitSoftware;
  const int qos_fd = request_cpu_dma_latency_if_asked(fixed.loop, realtime);  // held open while rpemd runs

  const std::string signing =
      keys.publish ? "signed with key id " + std::to_string(keys.publish->id()) : std::string("unsigned (no publish key)");
  loop_ = std::make_unique<LoopThread>(
      config_,
      LoopThread::Queues{std::move(samples_.consumer), std::move(commands_.consumer), std::move(reports_.producer)});
  seed_from_state_file();
  say_untested_soak();
  const char* source_type = SourceCatalogue::type(fixed.source);
  publisher_ = std::make_unique<PersistingPublisher>(
      fixed, PersistingPublisher::Identity{source_type, source_name_, state_file_status_, resumed_thermal_},
      PersistingPublisher::Queues{std::move(reports_.consumer), std::move(source_reports_.consumer),
                                  std::move(control_reports_.consumer)},
      std::move(keys.publish));  // the publisher thread holds it
  start_threads();
  while (!loop_->started()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  if (!loop_->setup_problems().empty()) {
    if (required) {
      std::fprintf(stderr, "rpemd: real-time set-up failed: %s\n", loop_->setup_problems().c_str());
      stop_threads();
      return io::kExitSoftware;
    }
    std::fprintf(stderr, "rpemd: warning: real-time set-up incomplete (%s); running best effort\n",
                 loop_->setup_problems().c_str());
  }
  source_thread_ = std::thread([this, policy = realtime ? fixed.receive_thread : ThreadPolicy{}, source_type] {
    name_thread((std::string("rpemd-") + source_type).c_str());
    (void)apply_thread_policy(policy);
    source_->run(stop_acquisition_, source_output_);
  });

  print_start(config_, source_name_, source_type, commands, signing);
  sd_notifyf(0, "READY=1\nSTATUS=estimating from %s", source_name_.c_str());

  {
    Control control(
        std::move(config_), [this] { return load_configuration(options_); },
        Control::Queues{std::move(commands_.producer), std::move(control_reports_.producer)}, loop_->timer(),
        std::move(commands));
    (void)control.run(signal_fd);
    config_ = control.running();
  }
  stop_threads();
  print_summary();
  if (qos_fd >= 0) ::close(qos_fd);
  if (signal_fd >= 0) ::close(signal_fd);
  std::fprintf(stderr, "rpemd: stopped\n");
  return io::kExitOk;
}

void Daemon::print_summary() const {
  const LoopTimer& t = loop_->timer();
  const LatencyHistogram& wake = t.run_latency();
  std::fprintf(stderr,
               "rpemd: loop wake-up latency over the run [us]: p50 %.0f, p99 %.0f, p99.9 %.0f, max %.1f; "
               "%lld overruns in %lld periods\n",
               wake.percentile(0.5), wake.percentile(0.99), wake.percentile(0.999), wake.max(),
               static_cast<long long>(t.overruns()), static_cast<long long>(t.periods()));
  if (!options_.histogram_path.empty()) {
    if (FILE* f = std::fopen(options_.histogram_path.c_str(), "w")) {
      for (int us = 0; us < LatencyHistogram::kBins; ++us) {
        if (wake.bin(us) > 0) std::fprintf(f, "%06d %lld\n", us, static_cast<long long>(wake.bin(us)));
      }
      std::fprintf(f, "# Histogram Overflows: %lld\n# Max Latencies: %.0f\n",
                   static_cast<long long>(wake.bin(LatencyHistogram::kBins)), wake.max());
      std::fclose(f);
    }
  }
  const WideLatencyHistogram& rx = publisher_->rx_to_publish();
  if (rx.count() > 0) {
    std::fprintf(stderr, "rpemd: CAN receive -> LCM publish [us]: p50 %.0f, p99 %.0f, max %.1f (%lld estimates)\n",
                 rx.percentile(0.5), rx.percentile(0.99), rx.max(), static_cast<long long>(rx.count()));
  }
}

}  // namespace rpem::daemon
