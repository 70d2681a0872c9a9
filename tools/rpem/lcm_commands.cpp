// rpem listen [--prefix P] [--duration S] [--csv FILE] [--key FILE]
//                                                          prints (and records) rpemd's estimates; with a
//                                                          key, each one verified, FORGED or unverified
// rpem command [--prefix P] --key FILE --seq N reset|freeze|unfreeze|set [--psi-m WB --r-s OHM]
//              [--repeat K --interval-ms M] [--save FILE]  sends a supervisory command to rpemd (K times:
//                                                          sequence numbers N … N+K−1, M ms apart)
// rpem command --resend FILE [--flip-bit B]                sends saved bytes again (tests of rpemd's checks)
// rpem publish-estimate --psi-m WB [--key FILE]            publishes one RPEM_ESTIMATE (tests of consumers)
// rpem keygen --id N --out FILE                            writes a new key file (mode 0600)
// Keys: rpem/auth/key_file.hpp, docs/rpemd.md "Authentication".

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iterator>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <span>
#include <string_view>
#include <thread>
#include <vector>

#include "commands.hpp"
#include "option_checks.hpp"
#include "rpem/auth/key_file.hpp"
#include "rpem/command_t.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/daemon/signal_map_source.hpp"
#include "rpem/daemon/status_line.hpp"
#include "rpem/mirror/diagnostics_t.hpp"
#include "rpem/mirror/estimate_t.hpp"
#include "rpem/schema/decode.hpp"
#include "rpem/schema/text.hpp"

namespace rpem::tools {
namespace {

std::atomic<bool> g_lcm_stop{false};
void on_lcm_stop_signal(int) { g_lcm_stop = true; }

struct ListenOptions {
  std::string prefix;
  std::string url;
  double duration_s = 0.0;
  std::string csv;
  bool diagnostics = false;
  std::string key_file;
};

/// Loads --key FILE (if given) into a keyring; throws auth::KeyError.
auth::Keyring keyring_of(const std::string& key_file) {
  auth::Keyring keys;
  if (!key_file.empty()) keys.add(auth::load_key_file(key_file));
  return keys;
}

/// "verified", "FORGED" (a key this listener holds, a wrong MAC) or "unverified (why)".
std::string authenticity(const auth::Keyring& keys, const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  const std::span bytes(static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size);
  const std::int32_t id = auth::key_id_of(bytes);
  switch (auth::verify(keys, channel, bytes)) {
    case auth::Verdict::kVerified:
      return "verified";
    case auth::Verdict::kBadMac:
      return "FORGED";
    case auth::Verdict::kUnsigned:
      return "unverified (unsigned)";
    case auth::Verdict::kUnknownKey:
      return keys.empty() ? "unverified (no --key)" : "unverified (key id " + std::to_string(id) + " not held)";
    case auth::Verdict::kMalformed:
      break;
  }
  return "unverified (malformed)";
}

// What `rpem listen` prints is every field of each message, as the schema prints it (rpem/schema/text.hpp),
// after a head that shows some in its own words: a new field of a .lcm file reaches the line and the CSV
// without code here.

/// The fields the head of an estimate's line shows: each parameter with its status, then the temperatures.
constexpr std::array<std::string_view, 16> kEstimateHead{"sample_time_us", "state",        "speed_pu",    "psi_m_Wb",
                                                         "psi_m_adapting", "psi_m_age_s",  "psi_m_valid", "psi_m_converged",
                                                         "r_s_Ohm",        "r_s_adapting", "r_s_age_s",   "r_s_valid",
                                                         "r_s_converged",  "t_magnet_C",   "t_winding_C", "algorithm"};
static_assert(schema::has_fields<rpem::estimate_t>(kEstimateHead));
/// With a thermal network that has stepped (thermal_active), the head shows the fused temperatures too, in the
/// status line's words (daemon/status_line.hpp): these fields then leave the tail.
constexpr std::array<std::string_view, 9> kFusedFields{
    "thermal_active",    "t_magnet_fused_C",     "t_magnet_fused_sd_C", "t_magnet_source",         "t_magnet_observed_age_s",
    "t_winding_fused_C", "t_winding_fused_sd_C", "t_winding_source",    "t_winding_observed_age_s"};
static_assert(schema::has_fields<rpem::estimate_t>(kFusedFields));
constexpr std::array<std::string_view, kEstimateHead.size() + kFusedFields.size()> kEstimateHeadFused = [] {
  std::array<std::string_view, kEstimateHead.size() + kFusedFields.size()> all{};
  std::copy(kFusedFields.begin(), kFusedFields.end(), std::copy(kEstimateHead.begin(), kEstimateHead.end(), all.begin()));
  return all;
}();
/// A diagnostics line starts "diag UTIME:".
constexpr std::array<std::string_view, 1> kDiagnosticsHead{"utime"};
static_assert(schema::has_fields<rpem::diagnostics_t>(kDiagnosticsHead));

/// A signal_map source's decoder counters in its own terms (SignalMapCounters, docs/sources.md "Counted"),
/// which rpemd publishes in the can_* fields: printed as a line of their own for that source.
struct SourceCounter {
  std::string_view label;
  std::int64_t rpem::diagnostics_t::*field;
};
constexpr std::array<SourceCounter, 7> kSignalMapCounters{{
    {"frames", &rpem::diagnostics_t::can_frames},
    {"unknown_id", &rpem::diagnostics_t::can_unknown_id},
    {"wrong_length", &rpem::diagnostics_t::can_wrong_dlc},
    {"incomplete", &rpem::diagnostics_t::can_incomplete},
    {"non_finite", &rpem::diagnostics_t::can_invalid_value},
    {"stale", &rpem::diagnostics_t::can_stale},
    {"kernel_drops", &rpem::diagnostics_t::can_kernel_drops},
}};

struct Listener {
  std::ofstream csv;
  std::int64_t estimates = 0, diagnostics = 0;
  std::int64_t verified = 0, forged = 0, unverified = 0, malformed = 0;
  bool print_diagnostics = false;
  auth::Keyring keys;

  std::string check(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    std::string verdict = authenticity(keys, rbuf, channel);
    (verdict == "verified" ? verified : verdict == "FORGED" ? forged : unverified) += 1;
    return verdict;
  }

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

  /// The raw bytes decoded here, not by LCM's typed subscription (whose decode can throw outside any
  /// handler: schema/decode.hpp): a message that is not exactly one T is counted and named, never a crash.
  template <class T>
  bool decoded(const lcm::ReceiveBuffer* rbuf, const std::string& channel, T& m) {
    if (schema::decode_exactly(std::span(static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size), m)) return true;
    ++malformed;
    std::fprintf(stderr, "rpem listen: %s: %u bytes that are not one %s: ignored\n", channel.c_str(),
                 static_cast<unsigned>(rbuf->data_size), T::getTypeName());
    return false;
  }
  void on_estimate_bytes(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    rpem::estimate_t m;
    if (decoded(rbuf, channel, m)) on_estimate(rbuf, channel, &m);
  }
  void on_diagnostics_bytes(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    rpem::diagnostics_t m;
    if (decoded(rbuf, channel, m)) on_diagnostics(rbuf, channel, &m);
  }

  void on_estimate(const lcm::ReceiveBuffer* rbuf, const std::string& channel, const rpem::estimate_t* m) {
    ++estimates;
    const std::string verdict = check(rbuf, channel);
    const std::string fused = m->thermal_active ? "  " + daemon::fused_temperatures(*m) : std::string();
    const std::string tail =
        schema::format_fields(*m, m->thermal_active ? std::span<const std::string_view>(kEstimateHeadFused)
                                                    : std::span<const std::string_view>(kEstimateHead));
    std::printf(
        "%.3f s  state %d  n %+.3f pu  psi_m %.5f Wb %s  r_s %.5f Ohm %s  T_magnet %.1f C  T_winding %.1f C%s  %s  %s | %s\n",
        1e-6 * static_cast<double>(m->sample_time_us), m->state, m->speed_pu, m->psi_m_Wb,
        describe(m->psi_m_adapting, m->psi_m_age_s, m->psi_m_valid, m->psi_m_converged).c_str(), m->r_s_Ohm,
        describe(m->r_s_adapting, m->r_s_age_s, m->r_s_valid, m->r_s_converged).c_str(), m->t_magnet_C, m->t_winding_C,
        fused.c_str(), m->algorithm.c_str(), verdict.c_str(), tail.c_str());
    std::fflush(stdout);
    if (csv.is_open()) {
      csv << schema::csv_row(*m) << ',' << verdict.substr(0, verdict.find(' ')) << '\n';
      csv.flush();
    }
  }
  void on_diagnostics(const lcm::ReceiveBuffer* rbuf, const std::string& channel, const rpem::diagnostics_t* m) {
    ++diagnostics;
    const std::string verdict = check(rbuf, channel);
    if (!print_diagnostics) return;
    const auto utime = static_cast<long long>(m->utime);
    std::printf("diag %lld: %s | %s\n", utime, schema::format_fields(*m, kDiagnosticsHead).c_str(), verdict.c_str());
    if (m->source == daemon::SignalMapSource::kType) {
      std::string counters;
      for (const SourceCounter& c : kSignalMapCounters)
        counters += " " + std::string(c.label) + " " + std::to_string(m->*c.field);
      std::printf("diag %lld %s:%s\n", utime, daemon::SignalMapSource::kType, counters.c_str());
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
  try {
    listener.keys = keyring_of(o.key_file);
  } catch (const auth::KeyError& e) {
    std::fprintf(stderr, "rpem listen: %s\n", e.what());
    return kExitConfig;
  }
  if (!o.csv.empty()) {
    listener.csv.open(o.csv, std::ios::trunc);
    listener.csv << schema::csv_header<rpem::estimate_t>() << ",auth\n";
  }
  lcm.subscribe(o.prefix + "RPEM_ESTIMATE", &Listener::on_estimate_bytes, &listener);
  lcm.subscribe(o.prefix + "RPEM_DIAGNOSTICS", &Listener::on_diagnostics_bytes, &listener);
  std::signal(SIGINT, on_lcm_stop_signal);
  std::signal(SIGTERM, on_lcm_stop_signal);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.duration_s > 0 ? o.duration_s : 1e9);
  while (!g_lcm_stop && std::chrono::steady_clock::now() < end) lcm.handleTimeout(100);
  std::fprintf(stderr, "rpem listen: %lld estimates, %lld diagnostics; %lld verified, %lld FORGED, %lld unverified",
               static_cast<long long>(listener.estimates), static_cast<long long>(listener.diagnostics),
               static_cast<long long>(listener.verified), static_cast<long long>(listener.forged),
               static_cast<long long>(listener.unverified));
  if (listener.malformed > 0) std::fprintf(stderr, "; %lld malformed", static_cast<long long>(listener.malformed));
  std::fputc('\n', stderr);
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
  std::string key_file;
  std::string save;    ///< also write the (last) message's bytes here
  std::string resend;  ///< send these saved bytes instead
  int flip_bit = -1;   ///< with resend: flip this bit (0 = the first byte's lowest) first
};

/// Encodes `m` (key id from `key`, or 0) and signs it for `channel`.
template <class Message>
std::vector<std::uint8_t> encode_signed(Message& m, const std::optional<auth::Key>& key, const std::string& channel) {
  m.key_id = key ? key->id() : 0;
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  if (key) auth::sign(*key, channel, bytes);
  return bytes;
}

std::optional<auth::Key> optional_key(const std::string& file) {
  return file.empty() ? std::nullopt : std::optional<auth::Key>(auth::load_key_file(file));
}

int run_command(const CommandOptions& o) {
  lcm::LCM lcm(o.url);
  if (!lcm.good()) {
    std::fprintf(stderr, "rpem command: LCM is not available\n");
    return kExitIoError;
  }
  const std::string channel = o.prefix + "RPEM_COMMAND";
  if (!o.resend.empty()) {
    std::ifstream in(o.resend, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in.good() && !in.eof()) return kExitIoError;
    if (o.flip_bit >= 0) {
      if (static_cast<std::size_t>(o.flip_bit / 8) >= bytes.size()) {
        std::fprintf(stderr, "rpem command: --flip-bit %d is beyond the %zu bytes of %s\n", o.flip_bit, bytes.size(),
                     o.resend.c_str());
        return kExitUsage;
      }
      char& byte = bytes[static_cast<std::size_t>(o.flip_bit / 8)];
      byte = static_cast<char>(byte ^ (1 << (o.flip_bit % 8)));
    }
    lcm.publish(channel, bytes.data(), static_cast<unsigned>(bytes.size()));
    std::fprintf(stderr, "rpem command: resent %zu bytes of %s%s on %s\n", bytes.size(), o.resend.c_str(),
                 o.flip_bit >= 0 ? (" with bit " + std::to_string(o.flip_bit) + " flipped").c_str() : "", channel.c_str());
    return kExitOk;
  }
  std::optional<auth::Key> key;
  try {
    key = optional_key(o.key_file);
  } catch (const auth::KeyError& e) {
    std::fprintf(stderr, "rpem command: %s\n", e.what());
    return kExitConfig;
  }
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
    m.utime = core::unix_us();
    m.seq = o.seq + k;
    const std::vector<std::uint8_t> bytes = encode_signed(m, key, channel);
    if (lcm.publish(channel, bytes.data(), static_cast<unsigned>(bytes.size())) != 0) {
      std::fprintf(stderr, "rpem command: publish failed\n");
      return kExitIoError;
    }
    if (!o.save.empty())
      std::ofstream(o.save, std::ios::binary | std::ios::trunc)
          .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  if (!key)
    std::fprintf(
        stderr,
        "rpem command: warning: no --key: the command is unsigned, and rpemd applies it only with authentication: none\n");
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
  writes_file(cmd->add_option("--csv", opts->csv, "also write every estimate to this CSV"));
  cmd->add_flag("--diagnostics", opts->diagnostics, "print RPEM_DIAGNOSTICS too");
  cmd->add_option("--key", opts->key_file, "verify each message with this key file (rpemd's publish key)");
  return [cmd, opts]() { return cmd->parsed() ? run_listen(*opts) : -1; };
}

Runner add_command_command(CLI::App& app) {
  auto opts = std::make_shared<CommandOptions>();
  CLI::App* cmd = app.add_subcommand("command", "Send a supervisory command to rpemd (RPEM_COMMAND)");
  cmd->add_option("action", opts->action, "reset | freeze | unfreeze | set")
      ->check(CLI::IsMember({"reset", "freeze", "unfreeze", "set"}));
  cmd->add_option("--seq", opts->seq, "sequence number, larger than the last accepted one");
  const CLI::Option* psi_m = cmd->add_option("--psi-m", opts->psi_m_Wb, "set: magnet flux linkage [Wb]");
  const CLI::Option* r_s = cmd->add_option("--r-s", opts->r_s_Ohm, "set: stator resistance [Ohm]");
  cmd->callback([opts, psi_m, r_s] {
    if (opts->resend.empty() && !opts->malformed && opts->action.empty()) throw CLI::RequiredError("action");
    // `set` replaces both initial values: an omitted one would be sent as 0, not "keep it".
    const bool set = opts->action == "set";
    for (const CLI::Option* o : {psi_m, r_s}) {
      if (set && o->count() == 0)
        throw CLI::ValidationError(o->get_name(),
                                   "set needs both --psi-m WB and --r-s OHM (identification starts over "
                                   "from them)");
      if (!set && !opts->action.empty() && o->count() > 0)
        throw CLI::ValidationError(o->get_name(), "is for set only, not " + opts->action);
    }
  });
  cmd->add_option("--prefix", opts->prefix, "channel prefix of the rpemd instance");
  cmd->add_option("--lcm-url", opts->url, "LCM URL (default: LCM's default)");
  cmd->add_option("--key", opts->key_file, "sign with this key file (one of rpemd's command keys)");
  cmd->add_option("--save", opts->save, "also write the message's bytes to this file");
  cmd->add_option("--resend", opts->resend, "send the bytes of a file written by --save instead (a test of rpemd's checks)");
  cmd->add_option("--flip-bit", opts->flip_bit, "with --resend: flip this bit first (0: the first byte's lowest)")
      ->check(CLI::Range(0, 1 << 20));
  cmd->add_flag("--malformed", opts->malformed, "send an undecodable message (a test of rpemd's input checks)");
  cmd->add_option("--repeat", opts->repeat, "send it this many times, with consecutive sequence numbers")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{10'000'000}));
  cmd->add_option("--interval-ms", opts->interval_ms, "with --repeat: this long between sends [ms]")
      ->check(CLI::Range(0.0, 60'000.0));
  return [cmd, opts]() { return cmd->parsed() ? run_command(*opts) : -1; };
}

Runner add_publish_estimate_command(CLI::App& app) {
  struct Options {
    std::string prefix, url, key_file;
    double psi_m_Wb = 1.0, r_s_Ohm = 1.0;
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("publish-estimate", "Publish one RPEM_ESTIMATE (a test of consumers' verification)");
  cmd->add_option("--psi-m", opts->psi_m_Wb, "magnet flux linkage [Wb]");
  cmd->add_option("--r-s", opts->r_s_Ohm, "stator resistance [Ohm]");
  cmd->add_option("--key", opts->key_file, "sign with this key file (else unsigned)");
  cmd->add_option("--prefix", opts->prefix, "channel prefix");
  cmd->add_option("--lcm-url", opts->url, "LCM URL (default: LCM's default)");
  return [cmd, opts]() {
    if (!cmd->parsed()) return -1;
    lcm::LCM lcm(opts->url);
    if (!lcm.good()) return kExitIoError;
    std::optional<auth::Key> key;
    try {
      key = optional_key(opts->key_file);
    } catch (const auth::KeyError& e) {
      std::fprintf(stderr, "rpem publish-estimate: %s\n", e.what());
      return kExitConfig;
    }
    rpem::estimate_t m{};
    m.utime = core::unix_us();
    m.psi_m_Wb = opts->psi_m_Wb;
    m.r_s_Ohm = opts->r_s_Ohm;
    m.psi_m_valid = m.r_s_valid = true;
    m.state = 1;
    m.algorithm = "sga";
    const std::string channel = opts->prefix + "RPEM_ESTIMATE";
    const std::vector<std::uint8_t> bytes = encode_signed(m, key, channel);
    return lcm.publish(channel, bytes.data(), static_cast<unsigned>(bytes.size())) == 0 ? kExitOk : kExitIoError;
  };
}

Runner add_keygen_command(CLI::App& app) {
  struct Options {
    std::int32_t id = 1;
    std::string out;
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("keygen", "Write a new random key file (mode 0600) for rpemd's channels");
  cmd->add_option("--id", opts->id, "key id, 1..2147483647 (a new id for each new key: rotation)")
      ->check(CLI::Range(1, 2147483647));
  cmd->add_option("--out", opts->out, "the key file to create (never replaced)")->required();
  return [cmd, opts]() {
    if (!cmd->parsed()) return -1;
    try {
      auth::write_key_file(opts->out, auth::generate_key(opts->id));
    } catch (const auth::KeyError& e) {
      std::fprintf(stderr, "rpem keygen: %s\n", e.what());
      return kExitIoError;
    }
    std::fprintf(stderr, "rpem keygen: key id %d written to %s (mode 0600)\n", opts->id, opts->out.c_str());
    return kExitOk;
  };
}

}  // namespace rpem::tools
