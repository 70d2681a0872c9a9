// rpem listen [--prefix P] [--duration S] [--csv FILE]      prints (and records) rpemd's estimates
// rpem command [--prefix P] --seq N reset|freeze|unfreeze|set [--psi-m WB --r-s OHM] [--repeat K --interval-ms M]
//                                                          sends a supervisory command to rpemd (K times:
//                                                          sequence numbers N … N+K−1, M ms apart)

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <thread>

#include "commands.hpp"
#include "rpem/command_t.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/diagnostics_t.hpp"
#include "rpem/estimate_t.hpp"

namespace rpem::tools {
namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

struct ListenOptions {
  std::string prefix;
  std::string url;
  double duration_s = 0.0;
  std::string csv;
  bool diagnostics = false;
};

struct Listener {
  std::ofstream csv;
  std::int64_t estimates = 0, diagnostics = 0;
  bool print_diagnostics = false;

  /// "adapting", "held 28.0 s" (since its last adaptation) or "initial" (never adapted), then
  /// "valid" and "converged" where they hold.
  static std::string describe(bool adapting, double age_s, bool valid, bool converged) {
    char held[32];
    std::snprintf(held, sizeof held, "held %.1f s", age_s);
    std::string s = adapting ? "adapting" : age_s >= 0.0 ? held : "initial";
    if (valid) s += " valid";
    if (converged) s += " converged";
    return s;
  }

  void on_estimate(const lcm::ReceiveBuffer*, const std::string&, const rpem::estimate_t* m) {
    ++estimates;
    std::printf("%.3f s  state %d  n %+.3f pu  psi_m %.5f Wb %s  r_s %.5f Ohm %s  T_magnet %.1f C  T_winding %.1f C  %s\n",
                1e-6 * static_cast<double>(m->sample_time_us), m->state, m->speed_pu, m->psi_m_Wb,
                describe(m->psi_m_adapting, m->psi_m_age_s, m->psi_m_valid, m->psi_m_converged).c_str(), m->r_s_Ohm,
                describe(m->r_s_adapting, m->r_s_age_s, m->r_s_valid, m->r_s_converged).c_str(), m->t_magnet_C,
                m->t_winding_C, m->algorithm.c_str());
    std::fflush(stdout);
    if (csv.is_open()) {
      csv << m->utime << ',' << m->sample_time_us << ',' << m->samples << ',' << m->psi_m_Wb << ',' << m->r_s_Ohm << ','
          << m->t_magnet_C << ',' << m->t_winding_C << ',' << m->speed_pu << ',' << int(m->psi_m_valid) << ','
          << int(m->r_s_valid) << ',' << int(m->psi_m_converged) << ',' << int(m->r_s_converged) << ','
          << int(m->psi_m_adapting) << ',' << int(m->r_s_adapting) << ',' << int(m->frozen) << ',' << int(m->state) << ','
          << m->psi_m_age_s << ',' << m->r_s_age_s << '\n';
      csv.flush();
    }
  }
  void on_diagnostics(const lcm::ReceiveBuffer*, const std::string&, const rpem::diagnostics_t* m) {
    ++diagnostics;
    if (!print_diagnostics) return;
    std::printf("diag %lld: state %d samples %lld resyncs %lld overruns %lld latency p99 %.1f us max %.1f us | rx->publish p99 %.0f us | can frames %lld "
                "lost %lld crc %lld dlc %lld unknown %lld gaps %lld kernel drops %lld reopens %lld | queue drops in %lld "
                "out %lld | publish failures %lld | commands %lld malformed %lld rejected %lld last %lld:%d | applied %lld "
                "sequence errors %lld | reload requests %lld reloads %lld invalid %lld restart required %lld busy %lld | "
                "state file %d\n",
                static_cast<long long>(m->utime), static_cast<int>(m->state), static_cast<long long>(m->samples),
                static_cast<long long>(m->resyncs),
                static_cast<long long>(m->overruns), m->wakeup_latency_p99_us, m->wakeup_latency_max_us,
                m->rx_to_publish_p99_us,
                static_cast<long long>(m->can_frames), static_cast<long long>(m->can_frames_lost),
                static_cast<long long>(m->can_crc_error), static_cast<long long>(m->can_wrong_dlc),
                static_cast<long long>(m->can_unknown_id), static_cast<long long>(m->can_gaps),
                static_cast<long long>(m->can_kernel_drops), static_cast<long long>(m->can_reopens),
                static_cast<long long>(m->input_queue_drops), static_cast<long long>(m->output_queue_drops),
                static_cast<long long>(m->publish_failures), static_cast<long long>(m->commands_received),
                static_cast<long long>(m->commands_malformed), static_cast<long long>(m->commands_rejected),
                static_cast<long long>(m->last_command_seq), m->last_command_result,
                static_cast<long long>(m->commands_applied), static_cast<long long>(m->command_sequence_errors),
                static_cast<long long>(m->config_reload_requests), static_cast<long long>(m->config_reloads),
                static_cast<long long>(m->config_reloads_invalid), static_cast<long long>(m->config_reloads_restart_required),
                static_cast<long long>(m->config_reloads_busy), m->state_file_status);
    if (m->source == "vesc") {
      std::printf("diag %lld vesc: polls %lld replies %lld timeouts %lld late %lld unrequested %lld stolen_reads %lld "
                  "short_windows %lld buffer_errors %lld bad_replies %lld short_replies %lld statuses %lld "
                  "send_failures %lld foreign %lld\n",
                  static_cast<long long>(m->utime), static_cast<long long>(m->vesc_polls),
                  static_cast<long long>(m->vesc_replies), static_cast<long long>(m->vesc_timeouts),
                  static_cast<long long>(m->vesc_late_replies), static_cast<long long>(m->vesc_unrequested_replies),
                  static_cast<long long>(m->vesc_stolen_reads), static_cast<long long>(m->vesc_short_windows),
                  static_cast<long long>(m->vesc_buffer_errors), static_cast<long long>(m->vesc_bad_replies),
                  static_cast<long long>(m->vesc_short_replies), static_cast<long long>(m->vesc_statuses),
                  static_cast<long long>(m->vesc_send_failures), static_cast<long long>(m->can_foreign));
    }
    std::fflush(stdout);
  }
};

int run_listen(const ListenOptions& o) {
  lcm::LCM lcm(o.url);
  if (!lcm.good()) {
    std::fprintf(stderr, "rpem listen: LCM is not available\n");
    return kExitIoError;
  }
  Listener listener;
  listener.print_diagnostics = o.diagnostics;
  if (!o.csv.empty()) {
    listener.csv.open(o.csv, std::ios::trunc);
    listener.csv << "utime,sample_time_us,samples,psi_m,r_s,T_magnet,T_winding,n_pu,psi_m_valid,r_s_valid,"
                    "psi_m_converged,r_s_converged,psi_m_adapting,r_s_adapting,frozen,state,psi_m_age_s,r_s_age_s\n";
  }
  lcm.subscribe(o.prefix + "RPEM_ESTIMATE", &Listener::on_estimate, &listener);
  lcm.subscribe(o.prefix + "RPEM_DIAGNOSTICS", &Listener::on_diagnostics, &listener);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.duration_s > 0 ? o.duration_s : 1e9);
  while (!g_stop && std::chrono::steady_clock::now() < end) lcm.handleTimeout(100);
  std::fprintf(stderr, "rpem listen: %lld estimates, %lld diagnostics\n", static_cast<long long>(listener.estimates),
               static_cast<long long>(listener.diagnostics));
  return listener.estimates > 0 ? kExitOk : 1;
}

struct CommandOptions {
  std::string prefix;
  std::string url;
  std::int64_t seq = 0;
  std::string action;
  double psi_m_Wb = 0.0;
  double r_s_Ohm = 0.0;
  bool malformed = false;
  std::int64_t repeat = 1;
  double interval_ms = 0.0;
};

int run_command(const CommandOptions& o) {
  lcm::LCM lcm(o.url);
  if (!lcm.good()) {
    std::fprintf(stderr, "rpem command: LCM is not available\n");
    return kExitIoError;
  }
  const std::string channel = o.prefix + "RPEM_COMMAND";
  if (o.malformed) {
    const char junk[] = "this is not an rpem command_t";
    lcm.publish(channel, junk, sizeof junk);
    std::fprintf(stderr, "rpem command: sent %zu bytes of junk on %s\n", sizeof junk, channel.c_str());
    return kExitOk;
  }
  rpem::command_t m{};
  m.command = o.action == "reset"      ? rpem::command_t::RESET
              : o.action == "freeze"   ? rpem::command_t::FREEZE
              : o.action == "unfreeze" ? rpem::command_t::UNFREEZE
                                       : rpem::command_t::SET_VALUES;
  m.psi_m_Wb = o.psi_m_Wb;
  m.r_s_Ohm = o.r_s_Ohm;
  const std::int64_t period_ns = static_cast<std::int64_t>(o.interval_ms * 1e6);
  const std::int64_t start_ns = core::now_ns(CLOCK_MONOTONIC);
  for (std::int64_t k = 0; k < o.repeat; ++k) {
    if (k > 0) core::sleep_until_ns(CLOCK_MONOTONIC, start_ns + k * period_ns);
    m.utime = core::now_ns(CLOCK_REALTIME) / 1000;
    m.seq = o.seq + k;
    if (lcm.publish(channel, &m) != 0) {
      std::fprintf(stderr, "rpem command: publish failed\n");
      return kExitIoError;
    }
  }
  std::fprintf(stderr, "rpem command: %s (seq %lld%s) sent on %s; see RPEM_DIAGNOSTICS for the acknowledgement\n",
               o.action.c_str(), static_cast<long long>(o.seq),
               o.repeat > 1 ? (" to " + std::to_string(o.seq + o.repeat - 1)).c_str() : "", channel.c_str());
  return kExitOk;
}

}  // namespace

Runner add_listen_command(CLI::App& app) {
  auto opts = std::make_shared<ListenOptions>();
  CLI::App* cmd = app.add_subcommand("listen", "Print rpemd's estimates from LCM (and record them as CSV)");
  cmd->add_option("--prefix", opts->prefix, "channel prefix of the rpemd instance");
  cmd->add_option("--lcm-url", opts->url, "LCM URL (default: LCM's default)");
  cmd->add_option("--duration", opts->duration_s, "stop after this many seconds");
  cmd->add_option("--csv", opts->csv, "also write every estimate to this CSV");
  cmd->add_flag("--diagnostics", opts->diagnostics, "print RPEM_DIAGNOSTICS too");
  return [cmd, opts]() { return cmd->parsed() ? run_listen(*opts) : -1; };
}

Runner add_command_command(CLI::App& app) {
  auto opts = std::make_shared<CommandOptions>();
  CLI::App* cmd = app.add_subcommand("command", "Send a supervisory command to rpemd (RPEM_COMMAND)");
  cmd->add_option("action", opts->action, "reset | freeze | unfreeze | set")
      ->check(CLI::IsMember({"reset", "freeze", "unfreeze", "set"}));
  cmd->add_option("--seq", opts->seq, "sequence number, larger than the last accepted one");
  cmd->add_option("--psi-m", opts->psi_m_Wb, "set: magnet flux linkage [Wb]");
  cmd->add_option("--r-s", opts->r_s_Ohm, "set: stator resistance [Ohm]");
  cmd->add_option("--prefix", opts->prefix, "channel prefix of the rpemd instance");
  cmd->add_option("--lcm-url", opts->url, "LCM URL (default: LCM's default)");
  cmd->add_flag("--malformed", opts->malformed, "send an undecodable message (a test of rpemd's input checks)");
  cmd->add_option("--repeat", opts->repeat, "send it this many times, with consecutive sequence numbers")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{10'000'000}));
  cmd->add_option("--interval-ms", opts->interval_ms, "with --repeat: this long between sends [ms]")
      ->check(CLI::Range(0.0, 60'000.0));
  return [cmd, opts]() { return cmd->parsed() ? run_command(*opts) : -1; };
}

}  // namespace rpem::tools
