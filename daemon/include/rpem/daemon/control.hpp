#pragma once
// rpemd's control thread — the main thread once the others run. It owns the running configuration and
// is the one producer of the loop's command queue: RPEM_COMMAND messages (through CommandGate) and
// reloads (SIGHUP) both enter here, from one poll(2) over a signalfd and the LCM socket, so the loop
// applies them in the order they were accepted, and a command is checked against the configuration
// the loop will be running when it gets there. It feeds systemd's watchdog while the loop's heartbeat
// advances, and returns on SIGTERM or SIGINT.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "rpem/daemon/command_gate.hpp"
#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/loop_timer.hpp"
#include "rpem/daemon/messages.hpp"
#include "rpem/daemon/spsc_queue.hpp"

namespace lcm {
class ReceiveBuffer;
}  // namespace lcm

namespace rpem::daemon {

/// Reloads: each SIGHUP is a request, then applied (queued for the loop) or refused for one reason.
struct ReloadCounters {
  std::int64_t requests = 0;
  std::int64_t invalid = 0;           ///< the file does not load (it names where and why in the log)
  std::int64_t restart_required = 0;  ///< it changes what only a restart applies (source, loop, …)
  std::int64_t busy = 0;              ///< the loop's command queue was full
};

class Control {
 public:
  struct Queues {
    SpscQueue<Command>::Producer to_loop;
    SpscQueue<ControlReport>::Producer to_publisher;
  };
  /// Reads the configuration again (the file, with the command line's overrides); throws io::InputError.
  using Reload = std::function<DaemonConfig()>;
  /// Whom commands must come from, and where the last accepted sequence number is kept.
  struct Commands {
    CommandKeys keys;
    std::int64_t last_accepted_seq = 0;
    std::string sequence_file;  ///< state_file.hpp: command_sequence_file()
  };

  Control(DaemonConfig running, Reload reload, Queues queues, const LoopTimer& loop, Commands commands);
  ~Control();

  /// Runs until SIGTERM or SIGINT arrives on `signal_fd` (a signalfd for SIGTERM, SIGINT and SIGHUP,
  /// which every thread blocks). Returns the signal.
  int run(int signal_fd);

  [[nodiscard]] const DaemonConfig& running() const noexcept { return running_; }
  [[nodiscard]] const ReloadCounters& reloads() const noexcept { return reloads_; }

 private:
  struct Lcm;
  void connect_lcm(std::int64_t now_ns);
  void on_command(const lcm::ReceiveBuffer* message, const std::string& channel);
  void log_rejection(CommandResult result, std::int64_t seq, std::int32_t key_id);
  void reload();
  void report();
  void watchdog(std::int64_t now_ns);

  DaemonConfig running_;
  Reload reload_;
  Queues queues_;
  const LoopTimer& loop_;
  class FileSequenceStore : public SequenceStore {
   public:
    explicit FileSequenceStore(std::string path) : path_(std::move(path)) {}
    bool store(std::int64_t seq) noexcept override;

   private:
    std::string path_;
  } sequence_store_;
  CommandGate gate_;
  /// Rejections are logged at most once per reason per kRejectionLogInterval; the rest are counted.
  std::array<std::int64_t, kCommandResults> rejection_log_next_ns_{};
  std::array<std::int64_t, kCommandResults> rejections_unlogged_{};
  ReloadCounters reloads_;
  std::unique_ptr<Lcm> lcm_;
  std::int64_t next_lcm_attempt_ns_ = 0;
  bool report_pending_ = true;
  bool watchdog_enabled_ = false;
  std::int64_t watchdog_interval_ns_ = 1'000'000'000;
  std::int64_t next_watchdog_ns_ = 0;
  std::uint64_t last_heartbeat_ = 0;
  bool wake_ahead_logged_ = false;
};

}  // namespace rpem::daemon
