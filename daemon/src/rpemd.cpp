// rpemd — online identification of the PMSM's magnet flux linkage and stator resistance.
//
//   rpemd [--config FILE.yaml] [--can IFACE] [--check-config]
//
// Without arguments it runs the paper's machine on the built-in simulated drive. Threads: source
// (CAN receive, or the simulated drive) → SPSC queue → estimator loop (SCHED_FIFO, pinned, fixed rate)
// → SPSC queue → publisher (LCM, state file, status line). The main thread handles signals (SIGTERM,
// SIGINT: stop; SIGHUP: reload gains and limits) and systemd notification and watchdog.

#include <signal.h>
#include <unistd.h>
#include <systemd/sd-daemon.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <thread>

#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/estimator_loop.hpp"
#include "rpem/daemon/publisher.hpp"
#include "rpem/daemon/realtime.hpp"
#include "rpem/daemon/sources.hpp"
#include "rpem/daemon/state_file.hpp"

namespace {

using namespace rpem::daemon;

constexpr int kExitConfig = 78;    // EX_CONFIG
constexpr int kExitSoftware = 70;  // EX_SOFTWARE

DaemonConfig load(const std::string& path) { return path.empty() ? builtin_daemon_config() : load_daemon_config(path); }

const char* realtime_name(RealtimeMode m) {
  return m == RealtimeMode::kRequired ? "required" : m == RealtimeMode::kOff ? "off" : "preferred";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rpemd: online identification of PMSM magnet flux linkage and stator resistance (docs/rpemd.md)"};
  std::string config_path, can_override, histogram_path;
  bool check_only = false;
  app.add_option("--config", config_path, "configuration YAML (default: built-in, simulated drive)");
  app.add_option("--can", can_override, "use this CAN interface as the source (overrides the configuration)");
  app.add_flag("--check-config", check_only, "validate the configuration and exit");
  app.add_option("--latency-histogram", histogram_path,
                 "at exit, write the loop's wake-up latency histogram (µs, count; as cyclictest -h) to this file");
  CLI11_PARSE(app, argc, argv);

  DaemonConfig config;
  try {
    config = load(config_path);
  } catch (const rpem::io::InputError& e) {
    std::fprintf(stderr, "rpemd: configuration error: %s\n", e.what());
    return kExitConfig;
  }
  if (!can_override.empty()) {
    config.source = SourceType::kCan;
    config.can_interface = can_override;
  }
  if (check_only) {
    std::printf("rpemd: %s is valid\n", config.source_file.c_str());
    return 0;
  }

  // Signals are handled here only: block them before any thread starts, so every thread inherits it.
  sigset_t signals;
  sigemptyset(&signals);
  for (int s : {SIGTERM, SIGINT, SIGHUP}) sigaddset(&signals, s);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  if (config.lock_memory && config.realtime != RealtimeMode::kOff) {
    const std::string problem = lock_memory();
    if (!problem.empty()) {
      if (config.realtime == RealtimeMode::kRequired) {
        std::fprintf(stderr, "rpemd: %s\n", problem.c_str());
        return kExitSoftware;
      }
      std::fprintf(stderr, "rpemd: warning: %s; continuing without locked memory\n", problem.c_str());
    }
  }

  int qos_fd = -1;  // held open while rpemd runs
  if (config.cpu_dma_latency_us >= 0 && config.realtime != RealtimeMode::kOff) {
    std::string problem;
    qos_fd = request_cpu_dma_latency(config.cpu_dma_latency_us, problem);
    if (qos_fd < 0) std::fprintf(stderr, "rpemd: note: %s; deep CPU idle states may add wake-up latency\n", problem.c_str());
  }

  SpscQueue<rpem::core::DriveSample> samples(8192);
  SpscQueue<Command> commands(16);
  SpscQueue<Report> reports(4096);
  SourceStats source_stats;

  std::unique_ptr<SampleSource> source;
  try {
    source = make_source(config, samples, source_stats);
  } catch (const rpem::io::InputError& e) {
    std::fprintf(stderr, "rpemd: configuration error: %s\n", e.what());
    return kExitConfig;
  }

  EstimatorLoop loop(config, samples, commands, reports);
  const auto& est = config.machine.estimator;
  const std::string state_path = resolve_state_file(config);
  const LoadedState loaded =
      load_state_file(state_path, config.state_max_age_s, est.psi_m_min_Wb, est.psi_m_max_Wb, est.r_s_min_Ohm, est.r_s_max_Ohm);
  if (loaded.status == StateFileStatus::kLoaded) loop.seed(loaded.estimates.psi_m_Wb, loaded.estimates.r_s_Ohm);
  if (loaded.status != StateFileStatus::kNone) std::fprintf(stderr, "rpemd: %s\n", loaded.message.c_str());

  Publisher publisher(config, source->name(), reports, commands, source_stats, loaded.status);
  std::atomic<bool> stop_acquisition{false}, stop_publisher{false};
  std::thread publisher_thread([&] { publisher.run(stop_publisher); });
  std::thread loop_thread([&] { loop.run(stop_acquisition); });
  while (!loop.started()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  if (!loop.setup_problems().empty()) {
    if (config.realtime == RealtimeMode::kRequired) {
      std::fprintf(stderr, "rpemd: real-time set-up failed: %s\n", loop.setup_problems().c_str());
      stop_acquisition = stop_publisher = true;
      loop_thread.join();
      publisher_thread.join();
      return kExitSoftware;
    }
    std::fprintf(stderr, "rpemd: warning: real-time set-up incomplete (%s); running best effort\n",
                 loop.setup_problems().c_str());
  }
  source->start(stop_acquisition);

  char wake_ahead[32];
  if (config.loop_wake_ahead_auto) {
    std::snprintf(wake_ahead, sizeof wake_ahead, "auto");
  } else {
    std::snprintf(wake_ahead, sizeof wake_ahead, "%.0f µs", config.loop_wake_ahead_s * 1e6);
  }
  std::fprintf(stderr,
               "rpemd: source %s '%s', loop %.0f µs (realtime %s, wake-ahead %s), machine %s, algorithm %s, LCM %s, "
               "channels %sRPEM_*, commands %s, state file %s\n",
               config.source == SourceType::kCan ? "can" : "sim", source->name().c_str(), config.loop_period_s * 1e6,
               realtime_name(config.realtime), wake_ahead, config.source_file.c_str(), rpem::io::to_string(est.algorithm),
               config.lcm_url.empty() ? "default" : config.lcm_url.c_str(), config.channel_prefix.c_str(),
               config.commands_enabled ? "enabled" : "disabled", state_path.c_str());
  sd_notifyf(0, "READY=1\nSTATUS=estimating from %s", source->name().c_str());

  // Watchdog: ping only while the loop's heartbeat advances.
  std::uint64_t watchdog_usec = 0;
  const bool watchdog = sd_watchdog_enabled(0, &watchdog_usec) > 0;
  const auto wait = std::chrono::microseconds(watchdog ? watchdog_usec / 2 : 1'000'000);
  std::uint64_t last_beat = loop.heartbeat();
  int exit_code = 0;
  bool wake_ahead_reported = !config.loop_wake_ahead_auto;
  while (true) {
    if (!wake_ahead_reported && loop.wake_ahead_ns() >= 0) {
      std::fprintf(stderr, "rpemd: timer anticipation calibrated: the loop wakes %.0f µs ahead of each deadline\n",
                   1e-3 * static_cast<double>(loop.wake_ahead_ns()));
      wake_ahead_reported = true;
    }
    timespec timeout{static_cast<time_t>(wait.count() / 1'000'000), static_cast<long>(wait.count() % 1'000'000) * 1000};
    const int sig = sigtimedwait(&signals, nullptr, &timeout);
    if (sig == SIGTERM || sig == SIGINT) {
      std::fprintf(stderr, "rpemd: %s: stopping\n", sig == SIGTERM ? "SIGTERM" : "SIGINT");
      sd_notify(0, "STOPPING=1");
      break;
    }
    if (sig == SIGHUP) {
      sd_notify(0, "RELOADING=1");
      try {
        const DaemonConfig fresh = load(config_path);
        Command c;
        c.kind = Command::Kind::kReconfigure;
        c.machine = fresh.machine.machine;
        c.settings = fresh.machine.estimator;
        c.temperature = fresh.temperature;
        c.validity = fresh.validity;
        if (!commands.push(c)) throw std::runtime_error("command queue full");
        std::fprintf(stderr, "rpemd: SIGHUP: reloaded gains and limits from %s\n", fresh.source_file.c_str());
      } catch (const std::exception& e) {
        publisher.counters().config_reload_failures.fetch_add(1);
        std::fprintf(stderr, "rpemd: SIGHUP: keeping the running configuration: %s\n", e.what());
      }
      sd_notify(0, "READY=1");
    }
    const std::uint64_t beat = loop.heartbeat();
    if (beat != last_beat) {
      if (watchdog) sd_notify(0, "WATCHDOG=1");
    } else {
      std::fprintf(stderr, "rpemd: the estimator loop has not run for %.1f s\n", 1e-6 * static_cast<double>(wait.count()));
    }
    last_beat = beat;
  }

  stop_acquisition = true;
  source->join();
  loop_thread.join();
  stop_publisher = true;
  publisher_thread.join();
  const LatencyHistogram& wake = loop.run_latency();
  std::fprintf(stderr,
               "rpemd: loop wake-up latency over the run [us]: p50 %.0f, p99 %.0f, p99.9 %.0f, max %.1f; "
               "%lld overruns in %lld periods\n",
               wake.percentile(0.5), wake.percentile(0.99), wake.percentile(0.999), wake.max(),
               static_cast<long long>(loop.overruns()), static_cast<long long>(loop.periods()));
  if (!histogram_path.empty()) {
    if (FILE* f = std::fopen(histogram_path.c_str(), "w")) {
      for (int us = 0; us < LatencyHistogram::kBins; ++us) {
        if (wake.bin(us) > 0) std::fprintf(f, "%06d %lld\n", us, static_cast<long long>(wake.bin(us)));
      }
      std::fprintf(f, "# Histogram Overflows: %lld\n# Max Latencies: %.0f\n",
                   static_cast<long long>(wake.bin(LatencyHistogram::kBins)), wake.max());
      std::fclose(f);
    }
  }
  if (publisher.rx_to_publish().count() > 0) {
    const LatencyHistogram& rx = publisher.rx_to_publish();
    std::fprintf(stderr, "rpemd: CAN receive -> LCM publish [us]: p50 %.0f, p99 %.0f, max %.1f (%lld estimates)\n",
                 rx.percentile(0.5), rx.percentile(0.99), rx.max(), static_cast<long long>(rx.count()));
  }
  if (qos_fd >= 0) ::close(qos_fd);
  std::fprintf(stderr, "rpemd: stopped\n");
  return exit_code;
}
