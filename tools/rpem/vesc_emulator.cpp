#include "vesc_emulator.hpp"

#include <array>
#include <algorithm>
#include <atomic>
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
#include "rpem/sim/vesc_motor.hpp"

namespace rpem::tools {
namespace {

std::atomic<bool> g_stop{false};
std::atomic<bool> g_toggle_silence{false};
void on_stop(int) { g_stop = true; }
void on_usr1(int) { g_toggle_silence = true; }

/// One of the firmware's two status threads (comm_can.c, cancom_status_thread/_2): the statuses whose bit
/// is set in `msgs`, every 1/rate.
struct StatusThread {
  double rate_Hz;
  std::uint32_t msgs;
  std::int64_t next_ns = 0;
};

struct EmulatorCounters {
  std::uint64_t requests = 0, replies = 0, reply_frames = 0, unsupported = 0, unheard = 0, statuses = 0,
                send_failures = 0, empty_reads = 0;
};

}  // namespace

void add_vesc_emulator_options(CLI::App* cmd, VescEmulatorOptions& o) {
  cmd->add_option("--vesc", o.interface, "answer as a VESC on this SocketCAN interface, in real time (docs/can-vesc.md)");
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
}

int run_vesc_emulator(sim::Scenario scenario, const VescEmulatorOptions& o) {
  namespace vesc = can::vesc;
  can::require_interface(o.interface);
  can::SocketCanChannel::Options co;
  co.interface = o.interface;
  co.fd = false;  // VESC speaks classic CAN
  co.receive_errors = false;
  can::SocketCanChannel channel(co);
  const auto id = static_cast<std::uint8_t>(o.controller_id);
  const std::string name = scenario.name;
  sim::VescMotor motor(std::move(scenario), {id, o.temp_fet_C});
  std::signal(SIGINT, on_stop);
  std::signal(SIGTERM, on_stop);
  std::signal(SIGUSR1, on_usr1);

  std::array<StatusThread, 2> threads{{{o.status_rate_1_Hz, o.status_msgs_1}, {o.status_rate_2_Hz, o.status_msgs_2}}};
  std::vector<can::ReceivedFrame> rx(64);
  std::array<can::CanFrame, vesc::buffer_frame_count(vesc::kMaxValuesPayload)> tx;
  std::array<std::uint8_t, vesc::kMaxValuesPayload> payload{};
  EmulatorCounters n;
  auto send = [&](const can::CanFrame& f) {
    if (!channel.send(f, 10)) ++n.send_failures;
  };
  std::optional<sim::TruthLogWriter> truth;
  if (!o.truth.empty()) truth.emplace(o.truth);
  std::int64_t next_truth_ns = 0;
  bool toggled_silent = false, was_quiet = false;
  std::fprintf(stderr, "rpem sim: VESC %d on %s, drive '%s' (pid %d; SIGUSR1 toggles silence)\n", o.controller_id,
               o.interface.c_str(), name.c_str(), static_cast<int>(getpid()));
  const std::int64_t start_ns = core::now_ns(CLOCK_MONOTONIC);
  const std::int64_t start_real_ns = core::now_ns(CLOCK_REALTIME);
  std::fprintf(stderr, "rpem sim: t = 0 at CLOCK_REALTIME %.6f s\n", 1e-9 * static_cast<double>(start_real_ns));
  while (!g_stop) {
    const std::size_t got = channel.receive(rx, 1);
    const std::int64_t t_ns = core::now_ns(CLOCK_MONOTONIC) - start_ns;
    if (o.duration_s > 0.0 && t_ns > static_cast<std::int64_t>(o.duration_s * 1e9)) break;
    if (g_toggle_silence.exchange(false)) toggled_silent = !toggled_silent;
    const double t_s = 1e-9 * static_cast<double>(t_ns);
    const bool quiet = toggled_silent || (o.silent_at_s >= 0.0 && t_s >= o.silent_at_s && t_s < o.silent_at_s + o.silent_for_s);
    if (quiet != was_quiet) std::fprintf(stderr, "rpem sim: VESC %d %s at %.3f s\n", o.controller_id, quiet ? "silent" : "back", t_s);
    was_quiet = quiet;

    for (std::size_t k = 0; k < got; ++k) {
      const auto request = vesc::parse_request(rx[k].frame, id);
      if (!request) continue;
      ++n.requests;
      // The firmware reads at the poll's arrival: the cycles up to its kernel receive time (which matters
      // when this loop was late and several polls wait in the socket).
      if (rx[k].kernel_rx_ns > 0) (void)motor.advance_to(std::min(rx[k].kernel_rx_ns - start_real_ns, t_ns));
      if (quiet) {  // off the bus: the firmware never sees the poll, and its averages keep running
        ++n.unheard;
        continue;
      }
      if (request->command != vesc::kCommGetValuesSelective || !request->has_mask || request->commands_send != 0) {
        ++n.unsupported;
        continue;
      }
      if (motor.cycles_since_read() == 0) ++n.empty_reads;
      const std::size_t len = vesc::encode_values(motor.read_values(), request->mask, payload);
      // send_packet_wrapper → comm_can_send_buffer(rx_buffer_last_id, …, rx_buffer_response_type = 1)
      const std::size_t frames = vesc::buffer_frames(request->sender, id, 1, {payload.data(), len}, tx);
      for (std::size_t f = 0; f < frames; ++f) send(tx[f]);
      ++n.replies;
      n.reply_frames += frames;
    }
    const bool running = motor.advance_to(t_ns);  // false: the scenario ended
    if (truth && motor.time_ns() >= next_truth_ns) {
      truth->write(motor.truth());
      next_truth_ns = motor.time_ns() + 10'000'000;
    }
    for (StatusThread& th : threads) {
      if (th.rate_Hz <= 0.0) continue;
      const auto period_ns = static_cast<std::int64_t>(1e9 / th.rate_Hz);
      if (th.next_ns < t_ns - 1'000'000'000) th.next_ns = t_ns;  // after a stall of over 1 s, no burst
      for (; th.next_ns <= t_ns; th.next_ns += period_ns) {  // late loops catch up: the rate holds on average
        if (quiet) continue;
        for (int number = 1; number <= 6; ++number) {
          if (((th.msgs >> (number - 1)) & 1U) == 0) continue;
          send(vesc::status_frame(motor.status(number)));
          ++n.statuses;
        }
      }
    }
    if (!running) break;
  }
  std::fprintf(stderr,
               "rpem sim: VESC %d stopped at %.3f s simulated: %llu polls, %llu replies in %llu frames, %llu unheard "
               "while silent, %llu unsupported, %llu reads with no control cycle since the previous, %llu status "
               "frames, %llu frames the interface dropped\n",
               o.controller_id, 1e-9 * static_cast<double>(motor.time_ns()), static_cast<unsigned long long>(n.requests),
               static_cast<unsigned long long>(n.replies), static_cast<unsigned long long>(n.reply_frames),
               static_cast<unsigned long long>(n.unheard), static_cast<unsigned long long>(n.unsupported),
               static_cast<unsigned long long>(n.empty_reads), static_cast<unsigned long long>(n.statuses),
               static_cast<unsigned long long>(n.send_failures));
  return kExitOk;
}

}  // namespace rpem::tools
