#include "vesc_emulator.hpp"

#include <unistd.h>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <optional>

#include <vector>

#include "commands.hpp"
#include "rpem/can/socketcan.hpp"
#include "rpem/can/vesc_firmware.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/sim/truth_log.hpp"
#include "rpem/sim/vesc_on_demand.hpp"

namespace rpem::tools {
namespace {

std::atomic<bool> g_stop{false};
std::atomic<bool> g_toggle_silence{false};
void on_stop(int) { g_stop = true; }
void on_usr1(int) { g_toggle_silence = true; }

/// Upper edges of the reply-delay classes [ms]: a reply's last frame sent this long after its poll's kernel
/// receive time, at most (the last class: later).
constexpr std::array<std::int64_t, 7> kDelayEdgesMs{1, 2, 5, 10, 20, 100, 1000};

/// A reply this late after its poll's arrival is the emulator's own stall (a VM under TCG on a busy host), not
/// the poller's: the report lists each, so a check can tell the two apart (tests/vm/check_vesc_rpemd.py).
constexpr std::int64_t kStallNs = 100'000'000;

/// One reply sent kStallNs or more after its poll arrived: when the poll arrived and how late the reply went out.
struct EmulatorStall {
  std::int64_t arrived_ns = 0, delay_ns = 0;
};

struct EmulatorCounters {
  std::uint64_t requests = 0, replies = 0, reply_frames = 0, unsupported = 0, unheard = 0, send_failures = 0;
  std::array<std::uint64_t, kDelayEdgesMs.size() + 1> reply_delay{};  ///< replies per delay class
  std::int64_t reply_delay_max_ns = 0;
  std::array<EmulatorStall, 64> stalls{};  ///< the first of them, in order
  std::uint64_t stall_count = 0;           ///< all of them

  void add_delay(std::int64_t arrived_ns, std::int64_t ns) noexcept {
    std::size_t k = 0;
    while (k < kDelayEdgesMs.size() && ns > kDelayEdgesMs[k] * 1'000'000) ++k;
    ++reply_delay[k];
    reply_delay_max_ns = std::max(reply_delay_max_ns, ns);
    if (ns < kStallNs) return;
    if (stall_count < stalls.size()) stalls[stall_count] = {arrived_ns, ns};
    ++stall_count;
  }
};

/// A poll timestamped longer ago than this is in the socket's queue: the drive may run up to now minus
/// this while idle without passing a poll not yet read (vcan timestamps in netif_rx, queues in softirq).
constexpr std::int64_t kSettleNs = 2'000'000;

}  // namespace

void add_vesc_emulator_options(CLI::App* cmd, VescEmulatorOptions& o) {
  CLI::Option* vesc = cmd->add_option(
      "--vesc", o.interface,
      "answer as a VESC on this SocketCAN interface, the drive run on demand up to each poll (docs/can-vesc.md)");
  cmd->add_option("--controller-id", o.controller_id, "the emulated VESC's controller id")
      ->check(CLI::Range(0, 254))
      ->needs(vesc);
  cmd->add_option("--fet-temperature", o.temp_fet_C, "the emulated power stage's temperature [C]")->needs(vesc);
  cmd->add_option("--status-rate-1", o.status_rate_1_Hz, "rate of status thread 1 [Hz], 0: off")
      ->check(CLI::Range(0.0, 1000.0))
      ->needs(vesc);
  cmd->add_option("--status-msgs-1", o.status_msgs_1, "statuses of thread 1, bit k = status k+1")
      ->check(CLI::Range(0, 63))
      ->needs(vesc);
  cmd->add_option("--status-rate-2", o.status_rate_2_Hz, "rate of status thread 2 [Hz], 0: off")
      ->check(CLI::Range(0.0, 1000.0))
      ->needs(vesc);
  cmd->add_option("--status-msgs-2", o.status_msgs_2, "statuses of thread 2, bit k = status k+1")
      ->check(CLI::Range(0, 63))
      ->needs(vesc);
  cmd->add_option("--silent-at", o.silent_at_s, "test aid: go silent (no replies, no statuses) at this time [s]")
      ->needs(vesc);
  cmd->add_option("--silent-for", o.silent_for_s, "test aid: …for this long [s] (SIGUSR1 toggles silence too)")
      ->check(CLI::NonNegativeNumber)
      ->needs(vesc);
  cmd->add_option("--duration", o.duration_s, "with --vesc: stop after this long [s] (default: the scenario's duration)")
      ->check(CLI::NonNegativeNumber)
      ->needs(vesc);
  cmd->add_option("--idle-step", o.idle_step_s,
                  "while no poll is pending: drive time run ahead per look at the socket, and the longest wait "
                  "for a poll between looks [s]")
      ->check(CLI::Range(1.0e-4, 1.0))
      ->capture_default_str()
      ->needs(vesc);
}

namespace {

namespace vesc = can::vesc;

/// Classic CAN (VESC speaks no FD), no error frames, and only polls to this controller or to all: one of
/// twelve emulators on a bus is not woken by the other eleven's polls, nor by any reply or status.
can::SocketCanChannel::Options channel_options(const VescEmulatorOptions& o) {
  can::SocketCanChannel::Options co;
  co.interface = o.interface;
  co.fd = false;
  co.receive_errors = false;
  const auto filters = vesc::controller_kernel_filters(static_cast<std::uint8_t>(o.controller_id));
  co.filters.assign(filters.begin(), filters.end());
  return co;
}

/// The emulated VESC while it runs: the drive on demand behind one socket, answering the polls it hears.
class VescEmulator {
 public:
  VescEmulator(sim::Scenario scenario, const VescEmulatorOptions& o, can::SocketCanChannel& channel,
               sim::TruthLogWriter* truth)
      : o_(o),
        channel_(channel),
        id_(static_cast<std::uint8_t>(o.controller_id)),
        drive_(std::move(scenario), drive_settings(o), truth),
        idle_step_ns_(static_cast<std::int64_t>(std::llround(o.idle_step_s * 1e9))) {}

  /// Until SIGINT/SIGTERM, the duration or the scenario's end. Drive time is the kernel's receive clock
  /// (CLOCK_REALTIME) minus the origin taken here (sim/vesc_on_demand.hpp).
  void run(const std::string& name) {
    std::fprintf(stderr, "rpem sim: VESC %d on %s, drive '%s' (pid %d; SIGUSR1 toggles silence)\n", o_.controller_id,
                 o_.interface.c_str(), name.c_str(), static_cast<int>(getpid()));
    origin_ns_ = core::now_ns(CLOCK_REALTIME);
    std::fprintf(stderr, "rpem sim: t = 0 at CLOCK_REALTIME %.6f s\n", core::to_seconds(origin_ns_));
    while (running_ && !g_stop) {
      const std::int64_t now = host_now();
      if (o_.duration_s > 0.0 && now > static_cast<std::int64_t>(o_.duration_s * 1e9)) break;
      const bool quiet = update_silence(core::to_seconds(now));
      const std::size_t got = channel_.receive_for(rx_, run_idle(now));
      for (std::size_t k = 0; k < got && running_; ++k) answer(rx_[k], quiet);
    }
  }

  void report() const;

 private:
  static sim::OnDemandVesc::Settings drive_settings(const VescEmulatorOptions& o) {
    sim::OnDemandVesc::Settings settings;
    settings.motor = {static_cast<std::uint8_t>(o.controller_id), o.temp_fet_C};
    settings.status = {{{o.status_rate_1_Hz, o.status_msgs_1}, {o.status_rate_2_Hz, o.status_msgs_2}}};
    return settings;
  }

  [[nodiscard]] std::int64_t host_now() const { return core::now_ns(CLOCK_REALTIME) - origin_ns_; }

  void send(const can::CanFrame& f) {
    if (!channel_.send(f, 10)) ++n_.send_failures;
  }

  /// Hands each status the drive emits on the bus.
  auto emitter() {
    return [this](const vesc::Status& s) { send(vesc::status_frame(s)); };
  }

  /// Silent from SIGUSR1's toggle or inside --silent-at/--silent-for; says so when that changes.
  bool update_silence(double t_s) {
    if (g_toggle_silence.exchange(false)) toggled_silent_ = !toggled_silent_;
    const bool quiet =
        toggled_silent_ || (o_.silent_at_s >= 0.0 && t_s >= o_.silent_at_s && t_s < o_.silent_at_s + o_.silent_for_s);
    if (quiet != was_quiet_) {
      std::fprintf(stderr, "rpem sim: VESC %d %s at %.3f s\n", o_.controller_id, quiet ? "silent" : "back", t_s);
    }
    was_quiet_ = quiet;
    drive_.set_silent(quiet);
    return quiet;
  }

  /// Idle: runs the drive ahead (statuses on their drive times) by one chunk, never into the settling
  /// window; returns how long to wait for a poll then (0 while the drive is still behind).
  std::int64_t run_idle(std::int64_t now) {
    const std::int64_t idle_to = now - kSettleNs;
    if (drive_.time_ns() < idle_to) {
      running_ = drive_.run_to(std::min(idle_to, drive_.time_ns() + idle_step_ns_), emitter());
      return 0;
    }
    return std::clamp<std::int64_t>(drive_.time_ns() + idle_step_ns_ - idle_to, 0, idle_step_ns_);
  }

  /// One received frame: a values request to this controller is answered with the drive's values at its
  /// arrival; anything else is counted.
  void answer(const can::ReceivedFrame& frame, bool quiet) {
    const auto request = vesc::parse_request(frame.frame, id_);
    if (!request) return;
    ++n_.requests;
    if (quiet) {  // off the bus: the firmware never sees the poll, and its averages keep running
      ++n_.unheard;
      return;
    }
    if (request->command != vesc::kCommGetValuesSelective || !request->has_mask || request->commands_send != 0) {
      ++n_.unsupported;
      return;
    }
    // The firmware reads at the poll's arrival: every cycle up to its kernel receive time.
    const std::int64_t arrived_ns = frame.kernel_rx_ns > 0 ? frame.kernel_rx_ns - origin_ns_ : host_now();
    const auto read = drive_.poll(arrived_ns, emitter());
    if (!read) {
      running_ = false;  // the scenario ended
      return;
    }
    const std::size_t len = vesc::encode_values(read->values, request->mask, payload_);
    // send_packet_wrapper → comm_can_send_buffer(rx_buffer_last_id, …, rx_buffer_response_type = 1)
    const std::size_t frames = vesc::buffer_frames(request->sender, id_, 1, {payload_.data(), len}, tx_);
    for (std::size_t f = 0; f < frames; ++f) send(tx_[f]);
    n_.add_delay(arrived_ns, host_now() - arrived_ns);
    ++n_.replies;
    n_.reply_frames += frames;
  }

  const VescEmulatorOptions& o_;
  can::SocketCanChannel& channel_;
  const std::uint8_t id_;
  sim::OnDemandVesc drive_;
  const std::int64_t idle_step_ns_;  ///< drive time run ahead per idle look, and the longest wait for a poll
  std::int64_t origin_ns_ = 0;
  std::vector<can::ReceivedFrame> rx_ = std::vector<can::ReceivedFrame>(64);
  std::array<can::CanFrame, vesc::buffer_frame_count(vesc::kMaxValuesPayload)> tx_;
  std::array<std::uint8_t, vesc::kMaxValuesPayload> payload_{};
  EmulatorCounters n_;
  bool toggled_silent_ = false, was_quiet_ = false, running_ = true;
};

void VescEmulator::report() const {
  const sim::OnDemandVesc::Counters& d = drive_.counters();
  const double lag_s = core::to_seconds(host_now() - drive_.time_ns());
  std::fprintf(stderr,
               "rpem sim: VESC %d stopped at %.3f s drive time (%.3f s behind the host): %llu polls, %llu replies in "
               "%llu frames, %llu unheard while silent, %llu unsupported, %llu reads with no control cycle since the "
               "previous, %llu polls read after the drive had passed them, %llu statuses, %llu frames the interface "
               "dropped\n",
               o_.controller_id, core::to_seconds(drive_.time_ns()), lag_s, static_cast<unsigned long long>(n_.requests),
               static_cast<unsigned long long>(n_.replies), static_cast<unsigned long long>(n_.reply_frames),
               static_cast<unsigned long long>(n_.unheard), static_cast<unsigned long long>(n_.unsupported),
               static_cast<unsigned long long>(d.empty_reads), static_cast<unsigned long long>(d.behind),
               static_cast<unsigned long long>(d.statuses), static_cast<unsigned long long>(n_.send_failures));
  std::fprintf(stderr, "rpem sim: VESC %d replies sent after their poll's arrival:", o_.controller_id);
  for (std::size_t k = 0; k < kDelayEdgesMs.size(); ++k) {
    std::fprintf(stderr, " <=%lld ms %llu,", static_cast<long long>(kDelayEdgesMs[k]),
                 static_cast<unsigned long long>(n_.reply_delay[k]));
  }
  std::fprintf(stderr, " later %llu; the latest %.3f s\n", static_cast<unsigned long long>(n_.reply_delay.back()),
               core::to_seconds(n_.reply_delay_max_ns));
  // The stalls, in the drive's (and the check's) time base: a poll's arrival [s] and its reply's delay [s].
  std::fprintf(stderr,
               "rpem sim: VESC %d stalled %.0f ms or more %llu times (arrival s:delay s, the first %zu):", o_.controller_id,
               1e3 * core::to_seconds(kStallNs), static_cast<unsigned long long>(n_.stall_count), n_.stalls.size());
  const std::size_t listed = std::min<std::size_t>(n_.stall_count, n_.stalls.size());
  for (std::size_t k = 0; k < listed; ++k) {
    std::fprintf(stderr, " %.3f:%.3f", core::to_seconds(n_.stalls[k].arrived_ns), core::to_seconds(n_.stalls[k].delay_ns));
  }
  std::fprintf(stderr, "\n");
}

}  // namespace

int run_vesc_emulator(sim::Scenario scenario, const VescEmulatorOptions& o) {
  can::require_interface(o.interface);
  can::SocketCanChannel channel(channel_options(o));
  const std::string name = scenario.name;
  std::signal(SIGINT, on_stop);
  std::signal(SIGTERM, on_stop);
  std::signal(SIGUSR1, on_usr1);
  std::optional<sim::TruthLogWriter> truth;
  if (!o.truth.empty()) truth.emplace(o.truth);
  VescEmulator emulator(std::move(scenario), o, channel, truth ? &*truth : nullptr);
  emulator.run(name);
  emulator.report();
  return kExitOk;
}

}  // namespace rpem::tools
