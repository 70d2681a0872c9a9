#include "rpem/daemon/control.hpp"

#include <poll.h>
#include <sys/signalfd.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <csignal>
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <span>

#include "rpem/core/clock.hpp"
#include "rpem/daemon/credentials.hpp"
#include "rpem/daemon/state_file.hpp"

namespace rpem::daemon {
namespace {

using Diag = rpem::diagnostics_t;

constexpr std::array<CounterRow<ReloadCounters>, 4> kReloadRows{{
    {&ReloadCounters::requests, &Diag::config_reload_requests},
    {&ReloadCounters::invalid, &Diag::config_reloads_invalid},
    {&ReloadCounters::restart_required, &Diag::config_reloads_restart_required},
    {&ReloadCounters::busy, &Diag::config_reloads_busy},
}};

constexpr std::int64_t kRejectionLogInterval_ns = 10 * core::kNsPerS;
constexpr int kMessagesPerWake = 64;  // then the signals get their turn again
constexpr int kCommandQueueCapacity = 1024;

}  // namespace

struct Control::Lcm {
  explicit Lcm(const std::string& url) : lcm(url) {}
  lcm::LCM lcm;
};

namespace {

const char* describe(CommandResult r) {
  switch (r) {
    case CommandResult::kNone:
      return "malformed (not one rpem.command_t)";
    case CommandResult::kApplied:
      return "applied";
    case CommandResult::kRejectedDisabled:
      return "commands are disabled";
    case CommandResult::kRejectedOldSequence:
      return "replayed or stale: sequence number not above the last accepted one";
    case CommandResult::kRejectedBadValues:
      return "values outside D_M";
    case CommandResult::kRejectedUnknown:
      return "unknown command";
    case CommandResult::kRejectedBusy:
      return "busy (the loop's queue is full)";
    case CommandResult::kRejectedUnauthenticated:
      return "unauthenticated (no key id, no MAC)";
    case CommandResult::kRejectedUnknownKey:
      return "unknown key id";
    case CommandResult::kRejectedBadMac:
      return "bad MAC (forged or altered)";
    case CommandResult::kRejectedNotPersisted:
      return "its sequence number could not be persisted";
  }
  return "?";
}

}  // namespace

bool Control::FileSequenceStore::store(std::int64_t seq) noexcept {
  try {
    const std::string problem = write_command_sequence(path_, seq);
    if (problem.empty()) return true;
    std::fprintf(stderr, "rpemd: cannot persist the command sequence number: %s\n", problem.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rpemd: cannot persist the command sequence number: %s\n", e.what());
  }
  return false;
}

Control::Control(DaemonConfig running, Reload reload, Queues queues, const LoopTimer& loop, Commands commands)
    : running_(std::move(running)),
      reload_(std::move(reload)),
      queues_(std::move(queues)),
      loop_(loop),
      sequence_store_(std::move(commands.sequence_file)),
      gate_(CommandPolicy::of(running_.live), queues_.to_loop, std::move(commands.keys), commands.last_accepted_seq,
            &sequence_store_) {
  std::uint64_t usec = 0;
  watchdog_enabled_ = sd_watchdog_enabled(0, &usec) > 0;
  if (watchdog_enabled_) watchdog_interval_ns_ = static_cast<std::int64_t>(usec) * 1000 / 2;
  wake_ahead_logged_ = !running_.fixed.loop.wake_ahead_auto;
}

Control::~Control() = default;

void Control::connect_lcm(std::int64_t now_ns) {
  if ((lcm_ && lcm_->lcm.good()) || now_ns < next_lcm_attempt_ns_) return;
  next_lcm_attempt_ns_ = now_ns + core::kNsPerS;
  const LcmConfig& c = running_.fixed.lcm;
  lcm_ = std::make_unique<Lcm>(c.url);
  if (!lcm_->lcm.good()) {
    std::fprintf(stderr, "rpemd: LCM not available for commands (%s); retrying\n",
                 c.url.empty() ? "default URL" : c.url.c_str());
    return;
  }
  lcm::Subscription* subscription = lcm_->lcm.subscribe(c.channel_prefix + "RPEM_COMMAND", &Control::on_command, this);
  // LCM keeps 30 undelivered messages per subscription by default and drops the rest; a reload (a few
  // milliseconds of YAML) must not cost the commands that arrive meanwhile.
  if (subscription != nullptr) subscription->setQueueCapacity(kCommandQueueCapacity);
}

void Control::on_command(const lcm::ReceiveBuffer* message, const std::string&) {
  const std::int64_t malformed = gate_.counters().malformed;
  // Admitted commands wait for commit() after this wake's messages (run()): one write for a burst.
  if (!gate_.handle(std::span(static_cast<const std::uint8_t*>(message->data), message->data_size), false)) {
    const bool decoded = gate_.counters().malformed == malformed;
    log_rejection(decoded ? gate_.last_result() : CommandResult::kNone, decoded ? gate_.last_seq() : 0,
                  decoded ? gate_.last_key_id() : 0);
  }
  report_pending_ = true;
}

void Control::log_rejection(CommandResult result, std::int64_t seq, std::int32_t key_id) {
  const auto k = static_cast<std::size_t>(result);
  const std::int64_t now = core::now_ns(CLOCK_MONOTONIC);
  if (now < rejection_log_next_ns_[k]) {
    ++rejections_unlogged_[k];
    return;
  }
  char more[96] = "";
  if (rejections_unlogged_[k] > 0) {
    std::snprintf(more, sizeof more, " (and %lld more such since the last line)",
                  static_cast<long long>(rejections_unlogged_[k]));
  }
  if (result == CommandResult::kNone) {
    std::fprintf(stderr, "rpemd: RPEM_COMMAND message rejected: %s%s\n", describe(result), more);
  } else {
    std::fprintf(stderr, "rpemd: RPEM_COMMAND seq %lld, key id %d rejected: %s%s\n", static_cast<long long>(seq), key_id,
                 describe(result), more);
  }
  rejections_unlogged_[k] = 0;
  rejection_log_next_ns_[k] = now + kRejectionLogInterval_ns;
}

void Control::reload() {
  ++reloads_.requests;
  report_pending_ = true;
  sd_notify(0, "RELOADING=1");
  try {
    const DaemonConfig fresh = reload_();
    const std::string key_problem = command_key_problem(fresh.live, gate_.keys().keys);
    if (!key_problem.empty()) {
      ++reloads_.invalid;
      std::fprintf(stderr, "rpemd: SIGHUP: keeping the running configuration: %s: %s\n", fresh.source_file.c_str(),
                   key_problem.c_str());
    } else if (const char* part = fixed_difference(running_.fixed, fresh.fixed); *part != '\0') {
      ++reloads_.restart_required;
      std::fprintf(stderr,
                   "rpemd: SIGHUP: %s changes `%s`, which only a restart applies; keeping the running configuration\n",
                   fresh.source_file.c_str(), part);
    } else {
      Command c;
      c.kind = Command::Kind::kReconfigure;
      c.live = fresh.live;
      if (!queues_.to_loop.push(c)) {
        ++reloads_.busy;
        std::fprintf(stderr, "rpemd: SIGHUP: the loop's command queue is full; keeping the running configuration\n");
      } else {
        running_.live = fresh.live;
        gate_.set_policy(CommandPolicy::of(running_.live));
        std::fprintf(stderr,
                     "rpemd: SIGHUP: reloaded gains, limits, model extensions, temperature, validity and commands from %s\n",
                     fresh.source_file.c_str());
      }
    }
  } catch (const std::exception& e) {
    ++reloads_.invalid;
    std::fprintf(stderr, "rpemd: SIGHUP: keeping the running configuration: %s\n", e.what());
  }
  sd_notify(0, "READY=1");
}

void Control::report() {
  if (!report_pending_) return;
  ControlReport r;
  gate_.report(r.rows);
  r.rows.set_all(kReloadRows, reloads_);
  r.commands_enabled = gate_.policy().enabled;
  r.last_command_seq = gate_.last_seq();
  r.last_command_result = gate_.last_result();
  if (queues_.to_publisher.push(r)) report_pending_ = false;  // else: again after the next event
}

void Control::watchdog(std::int64_t now_ns) {
  if (!wake_ahead_logged_ && loop_.wake_ahead_ns() >= 0) {
    std::fprintf(stderr, "rpemd: timer anticipation calibrated: the loop wakes %.0f µs ahead of each deadline\n",
                 1e-3 * static_cast<double>(loop_.wake_ahead_ns()));
    wake_ahead_logged_ = true;
  }
  if (now_ns < next_watchdog_ns_) return;
  next_watchdog_ns_ = now_ns + watchdog_interval_ns_;
  const std::uint64_t beat = loop_.heartbeat();
  if (beat != last_heartbeat_) {
    if (watchdog_enabled_) sd_notify(0, "WATCHDOG=1");
  } else {
    std::fprintf(stderr, "rpemd: the estimator loop has not run for %.1f s\n", core::to_seconds(watchdog_interval_ns_));
  }
  last_heartbeat_ = beat;
}

int Control::run(int signal_fd) {
  std::int64_t now = core::now_ns(CLOCK_MONOTONIC);
  next_watchdog_ns_ = now + watchdog_interval_ns_;
  last_heartbeat_ = loop_.heartbeat();
  while (true) {
    connect_lcm(now);
    report();
    std::array<pollfd, 2> fds{{{signal_fd, POLLIN, 0}, {-1, POLLIN, 0}}};
    if (lcm_ && lcm_->lcm.good()) fds[1].fd = lcm_->lcm.getFileno();
    std::int64_t wake = next_watchdog_ns_;
    if (!(lcm_ && lcm_->lcm.good())) wake = std::min(wake, next_lcm_attempt_ns_);
    if (report_pending_) wake = std::min(wake, now + 10'000'000);
    const int timeout_ms = static_cast<int>(std::clamp<std::int64_t>((wake - now) / 1'000'000 + 1, 0, 1000));
    (void)::poll(fds.data(), fds.size(), timeout_ms);
    if (fds[0].revents & POLLIN) {
      signalfd_siginfo info{};
      while (::read(signal_fd, &info, sizeof info) == static_cast<ssize_t>(sizeof info)) {
        const int sig = static_cast<int>(info.ssi_signo);
        if (sig == SIGTERM || sig == SIGINT) {
          std::fprintf(stderr, "rpemd: %s: stopping\n", sig == SIGTERM ? "SIGTERM" : "SIGINT");
          sd_notify(0, "STOPPING=1");
          report_pending_ = true;
          report();
          return sig;
        }
        if (sig == SIGHUP) reload();
      }
    }
    if (fds[1].fd >= 0 && (fds[1].revents & POLLIN)) {
      for (int k = 0; k < kMessagesPerWake && lcm_->lcm.handleTimeout(0) > 0; ++k) {
      }
      if (!gate_.commit()) log_rejection(CommandResult::kRejectedNotPersisted, gate_.last_seq(), gate_.last_key_id());
    }
    now = core::now_ns(CLOCK_MONOTONIC);
    watchdog(now);
  }
}

}  // namespace rpem::daemon
