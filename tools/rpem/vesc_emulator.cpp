#include "vesc_emulator.hpp"

#include <array>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <optional>
#include <unistd.h>

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

struct EmulatorCounters {
  std::uint64_t requests = 0, replies = 0, reply_frames = 0, unsupported = 0, unheard = 0, send_failures = 0;
  std::array<std::uint64_t, kDelayEdgesMs.size() + 1> reply_delay{};  ///< replies per delay class
  std::int64_t reply_delay_max_ns = 0;

  void add_delay(std::int64_t ns) noexcept {
    std::size_t k = 0;
    while (k < kDelayEdgesMs.size() && ns > kDelayEdgesMs[k] * 1'000'000) ++k;
    ++reply_delay[k];
    reply_delay_max_ns = std::max(reply_delay_max_ns, ns);
  }
};

/// A poll timestamped longer ago than this is in the socket's queue: the drive may run up to now minus
/// this while idle without passing a poll not yet read (vcan timestamps in netif_rx, queues in softirq).
constexpr std::int64_t kSettleNs = 2'000'000;

}  // namespace

void add_vesc_emulator_options(CLI::App* cmd, VescEmulatorOptions& o) {
  cmd->add_option("--vesc", o.interface, "answer as a VESC on this SocketCAN interface, the drive run on demand up to each poll (docs/can-vesc.md)");
  cmd->add_option("--controller-id", o.controller_id, "the emulated VESC's controller id")->check(CLI::Range(0, 254));
  cmd->add_option("--fet-temperature", o.temp_fet_C, "the emulated power stage's temperature [C]");
  cmd->add_option("--status-rate-1", o.status_rate_1_Hz, "rate of status thread 1 [Hz], 0: off")->check(CLI::Range(0.0, 1000.0));
  cmd->add_option("--status-msgs-1", o.status_msgs_1, "statuses of thread 1, bit k = status k+1")->check(CLI::Range(0, 63));
  cmd->add_option("--status-rate-2", o.status_rate_2_Hz, "rate of status thread 2 [Hz], 0: off")->check(CLI::Range(0.0, 1000.0));
  cmd->add_option("--status-msgs-2", o.status_msgs_2, "statuses of thread 2, bit k = status k+1")->check(CLI::Range(0, 63));
  cmd->add_option("--silent-at", o.silent_at_s, "test aid: go silent (no replies, no statuses) at this time [s]");
  cmd->add_option("--silent-for", o.silent_for_s, "test aid: …for this long [s] (SIGUSR1 toggles silence too)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--duration", o.duration_s, "stop after this long [s] (default: the scenario's duration)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--idle-step", o.idle_step_s,
                  "while no poll is pending: drive time run ahead per look at the socket, and the longest wait "
                  "for a poll between looks [s]")
      ->check(CLI::Range(1.0e-4, 1.0))
      ->capture_default_str();
}

int run_vesc_emulator(sim::Scenario scenario, const VescEmulatorOptions& o) {
  namespace vesc = can::vesc;
  can::require_interface(o.interface);
  can::SocketCanChannel::Options co;
  co.interface = o.interface;
  co.fd = false;  // VESC speaks classic CAN
  co.receive_errors = false;
  // Only polls to this controller or to all reach the socket: one of twelve emulators on a bus is not woken
  // by the other eleven's polls, nor by any reply or status.
  const auto filters = vesc::controller_kernel_filters(static_cast<std::uint8_t>(o.controller_id));
  co.filters.assign(filters.begin(), filters.end());
  can::SocketCanChannel channel(co);
  const auto id = static_cast<std::uint8_t>(o.controller_id);
  const std::string name = scenario.name;
  std::signal(SIGINT, on_stop);
  std::signal(SIGTERM, on_stop);
  std::signal(SIGUSR1, on_usr1);

  std::vector<can::ReceivedFrame> rx(64);
  std::array<can::CanFrame, vesc::buffer_frame_count(vesc::kMaxValuesPayload)> tx;
  std::array<std::uint8_t, vesc::kMaxValuesPayload> payload{};
  EmulatorCounters n;
  auto send = [&](const can::CanFrame& f) {
    if (!channel.send(f, 10)) ++n.send_failures;
  };
  auto emit = [&](const vesc::Status& s) { send(vesc::status_frame(s)); };
  std::optional<sim::TruthLogWriter> truth;
  if (!o.truth.empty()) truth.emplace(o.truth);
  sim::OnDemandVesc::Settings settings;
  settings.motor = {id, o.temp_fet_C};
  settings.status = {{{o.status_rate_1_Hz, o.status_msgs_1}, {o.status_rate_2_Hz, o.status_msgs_2}}};
  sim::OnDemandVesc drive(std::move(scenario), settings, truth ? &*truth : nullptr);
  bool toggled_silent = false, was_quiet = false, running = true;
  std::fprintf(stderr, "rpem sim: VESC %d on %s, drive '%s' (pid %d; SIGUSR1 toggles silence)\n", o.controller_id,
               o.interface.c_str(), name.c_str(), static_cast<int>(getpid()));
  // Drive time is the kernel's receive clock (CLOCK_REALTIME) minus this origin (sim/vesc_on_demand.hpp).
  const std::int64_t origin_ns = core::now_ns(CLOCK_REALTIME);
  std::fprintf(stderr, "rpem sim: t = 0 at CLOCK_REALTIME %.6f s\n", core::to_seconds(origin_ns));
  auto host_now = [&] { return core::now_ns(CLOCK_REALTIME) - origin_ns; };
  // Idle simulation between two looks at the socket (drive time), and the longest wait for a poll.
  const auto idle_step_ns = static_cast<std::int64_t>(std::llround(o.idle_step_s * 1e9));
  while (running && !g_stop) {
    const std::int64_t now = host_now();
    if (o.duration_s > 0.0 && now > static_cast<std::int64_t>(o.duration_s * 1e9)) break;
    if (g_toggle_silence.exchange(false)) toggled_silent = !toggled_silent;
    const double t_s = core::to_seconds(now);
    const bool quiet = toggled_silent || (o.silent_at_s >= 0.0 && t_s >= o.silent_at_s && t_s < o.silent_at_s + o.silent_for_s);
    if (quiet != was_quiet) std::fprintf(stderr, "rpem sim: VESC %d %s at %.3f s\n", o.controller_id, quiet ? "silent" : "back", t_s);
    was_quiet = quiet;
    drive.set_silent(quiet);

    // Idle: run the drive ahead (statuses on their drive times) in chunks, never into the settling window.
    const std::int64_t idle_to = now - kSettleNs;
    std::int64_t wait_ns = 0;
    if (drive.time_ns() < idle_to) {
      running = drive.run_to(std::min(idle_to, drive.time_ns() + idle_step_ns), emit);
    } else {
      wait_ns = std::clamp<std::int64_t>(drive.time_ns() + idle_step_ns - idle_to, 0, idle_step_ns);
    }
    const std::size_t got = channel.receive_for(rx, wait_ns);
    for (std::size_t k = 0; k < got && running; ++k) {
      const auto request = vesc::parse_request(rx[k].frame, id);
      if (!request) continue;
      ++n.requests;
      if (quiet) {  // off the bus: the firmware never sees the poll, and its averages keep running
        ++n.unheard;
        continue;
      }
      if (request->command != vesc::kCommGetValuesSelective || !request->has_mask || request->commands_send != 0) {
        ++n.unsupported;
        continue;
      }
      // The firmware reads at the poll's arrival: every cycle up to its kernel receive time.
      const std::int64_t arrived_ns = rx[k].kernel_rx_ns > 0 ? rx[k].kernel_rx_ns - origin_ns : host_now();
      const auto read = drive.poll(arrived_ns, emit);
      if (!read) {
        running = false;  // the scenario ended
        break;
      }
      const std::size_t len = vesc::encode_values(read->values, request->mask, payload);
      // send_packet_wrapper → comm_can_send_buffer(rx_buffer_last_id, …, rx_buffer_response_type = 1)
      const std::size_t frames = vesc::buffer_frames(request->sender, id, 1, {payload.data(), len}, tx);
      for (std::size_t f = 0; f < frames; ++f) send(tx[f]);
      n.add_delay(host_now() - arrived_ns);
      ++n.replies;
      n.reply_frames += frames;
    }
  }
  const sim::OnDemandVesc::Counters& d = drive.counters();
  const double lag_s = core::to_seconds(host_now() - drive.time_ns());
  std::fprintf(stderr,
               "rpem sim: VESC %d stopped at %.3f s drive time (%.3f s behind the host): %llu polls, %llu replies in "
               "%llu frames, %llu unheard while silent, %llu unsupported, %llu reads with no control cycle since the "
               "previous, %llu polls read after the drive had passed them, %llu statuses, %llu frames the interface "
               "dropped\n",
               o.controller_id, core::to_seconds(drive.time_ns()), lag_s,
               static_cast<unsigned long long>(n.requests), static_cast<unsigned long long>(n.replies),
               static_cast<unsigned long long>(n.reply_frames), static_cast<unsigned long long>(n.unheard),
               static_cast<unsigned long long>(n.unsupported), static_cast<unsigned long long>(d.empty_reads),
               static_cast<unsigned long long>(d.behind), static_cast<unsigned long long>(d.statuses),
               static_cast<unsigned long long>(n.send_failures));
  std::fprintf(stderr, "rpem sim: VESC %d replies sent after their poll's arrival:", o.controller_id);
  for (std::size_t k = 0; k < kDelayEdgesMs.size(); ++k) {
    std::fprintf(stderr, " <=%lld ms %llu,", static_cast<long long>(kDelayEdgesMs[k]),
                 static_cast<unsigned long long>(n.reply_delay[k]));
  }
  std::fprintf(stderr, " later %llu; the latest %.3f s\n", static_cast<unsigned long long>(n.reply_delay.back()),
               core::to_seconds(n.reply_delay_max_ns));
  return kExitOk;
}

}  // namespace rpem::tools
