// rpem thermal fit --log LOG.csv|FOLDER [--log-map MAP.yaml] --config CFG.yaml --out thermal.yaml
//                  [--start THERMAL.yaml | --nodes 2|3] [--fit-until-s S | --held-out-sessions N]
//                  [--winding-sensor-sigma-K K] [--period-s S] [--report DIR]
// Fits the machine's thermal network to what a log shows of its temperatures — a winding sensor, the
// coolant, the magnet temperature from ψ̂m and the winding's from r̂s (the estimator run over the log) —
// and writes the `thermal` section rpemd and `rpem estimate --thermal` read (docs/thermal.md). A magnet
// sensor in the log (T_magnet) is never used. A folder's logs are one machine's sessions, each recorded on its own and
// fitted together, each from its own start (docs/thermal.md, "A folder of logs").

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "log_folder.hpp"
#include "log_options.hpp"
#include "machine_option.hpp"
#include "option_checks.hpp"
#include "rpem/analysis/thermal/held_winding_column.hpp"
#include "rpem/analysis/thermal/thermal_fit.hpp"
#include "rpem/analysis/thermal/thermal_report.hpp"
#include "rpem/analysis/thermal/thermal_topology.hpp"
#include "rpem/io/errors.hpp"
#include "rpem/io/sample_counts.hpp"
#include "rpem/io/thermal_config.hpp"

namespace rpem::tools {
namespace {

struct ThermalFitCliOptions {
  std::string log, log_map, config, out, start, report;
  int nodes = 0;              ///< --nodes; 0: not given (2 without a network to start from)
  int held_out_sessions = 0;  ///< --held-out-sessions: a folder's last sessions, judged and not fitted
  double fit_until_s = std::numeric_limits<double>::quiet_NaN();
  std::optional<double> winding_sensor_sigma_K;  ///< --winding-sensor-sigma-K; wins over --start's
  double period_s = 0.0;
  double disturbance_time_constant_s = 0.0;  ///< 0: chosen by the likelihood
  bool keep_magnet_reference = false;
};

/// The winding sensor's σ where neither --winding-sensor-sigma-K nor --start gives one.
constexpr double kDefaultWindingSensorSigma_K = 1.0;

/// The winding sensor's σ: the option's, else --start's, else the default.
double winding_sensor_sigma_K(const ThermalFitCliOptions& o, const io::ThermalConfig& laws) {
  if (o.winding_sensor_sigma_K) return *o.winding_sensor_sigma_K;
  return laws.fusion.winding_sensor_sigma_K > 0.0 ? laws.fusion.winding_sensor_sigma_K : kDefaultWindingSensorSigma_K;
}

/// How the notes name the winding sensor's column.
constexpr const char* kWindingColumn = "the winding sensor (T_winding)";

/// The estimator run over --log: one log, or each log of a folder on its own, joined as one machine's sessions (a
/// folder's log that gives no step of the filter is left out, and said so). What each was read as and assumed goes
/// to stderr; the winding readings set aside as held (eq. 14.28b) to `set_aside`, for the fit's notes.
analysis::ThermalRecord record_sessions(const ThermalFitCliOptions& o, const io::MachineConfig& machine,
                                        const io::ThermalConfig& laws, std::vector<std::string>& set_aside) {
  const bool folder = std::filesystem::is_directory(o.log);
  std::vector<std::string> logs;
  if (folder) {
    for (const std::filesystem::path& p : logs_in_folder(o.log)) logs.push_back(p.string());
  } else {
    logs.push_back(o.log);
  }
  std::vector<analysis::ThermalRecord> sessions;
  for (const std::string& log : logs) {
    std::fprintf(stderr, "rpem thermal fit: running the estimator over %s\n", log.c_str());
    analysis::ThermalRecord r = analysis::record_thermal(io::log_source(log, o.log_map), machine, laws);
    std::fprintf(stderr, "rpem thermal fit: %s\n", r.read_as.c_str());
    if (const std::string note = io::assumed_frame_note(r.counts); !note.empty())
      std::fprintf(stderr, "rpem thermal fit: note: %s\n", note.c_str());
    const double sensor_sigma_K = winding_sensor_sigma_K(o, laws);
    const analysis::HeldWindingColumn held = analysis::drop_held_winding_readings(
        r, laws.fusion.filter.network.copper, sensor_sigma_K, laws.fusion.winding_sensor_time_constant_s);
    for (std::string& said : held.describe(kWindingColumn)) set_aside.push_back(std::move(said));
    if (!r.coolant) {
      std::fprintf(
          stderr,
          "rpem thermal fit: %s has no T_coolant column (or no reading in it): the coolant is taken as %.4g °C throughout "
          "(thermal.coolant_C); a coolant that moves shows as a model error (docs/thermal.md)\n",
          log.c_str(), laws.fusion.coolant_C);
    }
    if (folder && r.steps.empty()) {
      std::fprintf(stderr, "rpem thermal fit: %s gives no step of the thermal filter (%.3g s): left out\n", log.c_str(),
                   laws.fusion.observer.period_s);
      continue;
    }
    sessions.push_back(std::move(r));
  }
  if (!folder) return std::move(sessions.front());
  if (sessions.empty()) {
    throw io::DriveLogError(o.log, 0, 0, "", "no log in the folder gives a step of the thermal filter");
  }
  std::fprintf(stderr, "rpem thermal fit: %zu sessions of %s, each from its own start\n", sessions.size(), o.log.c_str());
  return analysis::join_sessions(std::move(sessions), o.log);
}

/// The median time between the filter's steps within a session (0 with fewer than two).
double median_step_s(const analysis::ThermalRecord& r) {
  std::vector<double> dt;
  for (std::size_t j = 0; j < r.session_first_step.size(); ++j) {
    for (std::size_t k = r.session_first_step[j] + 1; k < r.session_end(j); ++k) dt.push_back(r.t_s[k] - r.t_s[k - 1]);
  }
  if (dt.empty()) return 0.0;
  const auto middle = dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2);
  std::nth_element(dt.begin(), middle, dt.end());
  return *middle;
}

/// What the fit found, on the terminal: each signal's fit and held-out error, each parameter with its interval, what
/// the log cannot tell apart, the notes, and the noise the filter takes (the caller ends the line).
void print_fit(const analysis::ThermalFitResult& fit, const analysis::ThermalRecord& record) {
  for (const analysis::SignalFit& s : fit.signals) {
    std::printf("%s: %s in training (σ %.2g K); ", s.name.c_str(), analysis::training_span(s).c_str(), s.training_sigma_K);
    if (s.fit_points > 0) std::printf("fit %.3g K RMS, ", s.fit_rms_K);  // none in training: no figure of 0 K
    if (s.heldout_points == 0) {
      if (fit.training_steps == record.steps.size()) {
        std::printf("nothing held out (the training part, to %.6g s, takes the whole log)\n", fit.fit_until_s);
      } else {  // e.g. a held-out session without a winding sensor
        std::printf("nothing held out (none after the training part's end at %.6g s)\n", fit.fit_until_s);
      }
    } else {
      std::printf("held out %.3g K RMS (worst %.3g K)\n", s.heldout_rms_K, s.heldout_worst_K);
    }
  }
  for (const analysis::FittedParameter& p : fit.parameters) {
    if (p.half_width_rel <= 10.0) {
      std::printf("%s = %.5g%s (±%.3g %%%s)\n", p.name.c_str(), p.value, p.unit_after_value().c_str(),
                  100.0 * p.half_width_rel, p.identified ? "" : ", not identified");
    } else {
      std::printf("%s = %.5g%s (not identified: the log does not bound it)\n", p.name.c_str(), p.value,
                  p.unit_after_value().c_str());
    }
  }
  for (const std::string& s : fit.not_identifiable) std::printf("not identifiable together: %s\n", s.c_str());
  for (const std::string& s : fit.notes) std::printf("note: %s\n", s.c_str());
  std::printf("process noise %.3g K^2/s, disturbance drift %.3g W^2/s, correlation times", fit.process_noise_K2_per_s,
              fit.disturbance_W2_per_s);
  for (int i = 0; i < fit.config.fusion.filter.network.nodes; ++i)
    std::printf(" %s %.3g s", fit.config.node_names[static_cast<std::size_t>(i)].c_str(),
                fit.disturbance_time_constant_s[i]);
  std::printf("\n%s", analysis::coolant_drift_sentence(fit.coolant_drift).c_str());
}

/// How often the fit looks again at the winding sensor's column with the network it fitted (eq. 14.28c): each look
/// that sets readings aside is followed by a fit without them.
constexpr int kHeldReadingLooks = 2;

/// The fit, and again without the winding readings its own network's filter refuses as held (eq. 14.28c).
/// `start_for`: the network to start from for a record (its sensor may be gone); `set_aside`: the readings set aside
/// before the fit (eq. 14.28b). Every run set aside is one of the fit's notes (the terminal, thermal.yaml, the report).
template <class StartFor>
analysis::ThermalFitResult fit_without_held_readings(analysis::ThermalRecord& record, const StartFor& start_for,
                                                     const analysis::ThermalFitOptions& options,
                                                     std::vector<std::string> set_aside) {
  analysis::ThermalFitResult fit = analysis::fit_thermal(record, start_for(record), options);
  for (int look = 0; look < kHeldReadingLooks; ++look) {
    const analysis::HeldWindingColumn held = analysis::drop_winding_readings_the_network_holds(record, fit.config.fusion);
    if (held.runs.empty()) break;
    for (std::string& said : held.describe(kWindingColumn)) set_aside.push_back(std::move(said));
    fit = analysis::fit_thermal(record, start_for(record), options);
  }
  fit.notes.insert(fit.notes.begin(), set_aside.begin(), set_aside.end());
  return fit;
}

int run_thermal_fit(const ThermalFitCliOptions& o) {
  const io::MachineConfig machine = machine_config_or_builtin(o.config, "rpem thermal fit");
  const std::string config_name = o.config.empty() ? "builtin:paper-ipmsm" : o.config;
  io::ThermalConfig laws = o.start.empty() ? io::default_thermal_config(machine)
                                           : io::load_thermal_config(o.start, machine, io::NetworkRequired::kNo);
  if (o.period_s > 0.0) laws.fusion.observer.period_s = o.period_s;
  if (laws.has_network && o.nodes > 0) {
    std::fprintf(stderr,
                 "rpem thermal fit: --nodes %d: --start %s has a network of %d nodes to start from; give --nodes "
                 "with a start of laws only, or neither\n",
                 o.nodes, o.start.c_str(), laws.fusion.filter.network.nodes);
    return kExitUsage;
  }
  std::vector<std::string> set_aside;
  analysis::ThermalRecord record = record_sessions(o, machine, laws, set_aside);
  if (record.winding_sensor) laws.fusion.winding_sensor_sigma_K = winding_sensor_sigma_K(o, laws);
  const auto start_for = [&](const analysis::ThermalRecord& r) {
    return laws.has_network ? laws : analysis::default_topology(laws, r, o.nodes > 0 ? o.nodes : 2);
  };
  const io::ThermalConfig start = start_for(record);
  analysis::ThermalFitOptions options;
  options.fit_until_s = o.fit_until_s;
  // A --fit-until-s that leaves too short a training part is the command's fault, not the log's (64).
  if (const std::size_t training = analysis::steps_until(record, o.fit_until_s);
      !std::isnan(o.fit_until_s) && !record.t_s.empty() && training < analysis::kMinFitSteps) {
    std::fprintf(stderr,
                 "rpem thermal fit: --fit-until-s %.6g: %zu step%s of the thermal filter end by then, a fit needs at "
                 "least %zu; %s's steps end from %.6g to %.6g s\n",
                 o.fit_until_s, training, training == 1 ? "" : "s", analysis::kMinFitSteps, o.log.c_str(),
                 record.t_s.front(), record.t_s.back());
    return kExitUsage;
  }
  if (o.held_out_sessions > 0) {
    const std::size_t sessions = record.session_first_step.size();
    if (static_cast<std::size_t>(o.held_out_sessions) >= sessions) {
      std::fprintf(stderr,
                   "rpem thermal fit: --held-out-sessions %d: %s gives %zu session%s with steps of the filter; at least "
                   "one must be left to fit\n",
                   o.held_out_sessions, o.log.c_str(), sessions, sessions == 1 ? "" : "s");
      return kExitUsage;
    }
    // The training part ends with the last step before the first held-out session.
    options.fit_until_s =
        record.t_s[record.session_first_step[sessions - static_cast<std::size_t>(o.held_out_sessions)] - 1];
  }
  options.anchor_magnet_reference = !o.keep_magnet_reference;
  if (o.disturbance_time_constant_s > 0.0) options.disturbance_time_constant_s = o.disturbance_time_constant_s;
  std::fprintf(stderr,
               "rpem thermal fit: %zu steps of the filter, %.3g s apart (median; its period %.3g s, a row's interval "
               "where rows are further apart); fitting a %d-node network\n",
               record.steps.size(), median_step_s(record), start.fusion.observer.period_s,
               start.fusion.filter.network.nodes);
  const analysis::ThermalFitResult fit = fit_without_held_readings(record, start_for, options, std::move(set_aside));

  // A network every reader would refuse is not written (its report is: it shows what the log bounds).
  const std::optional<std::string> runaway = io::runaway_at_rating(fit.config, machine);
  if (!runaway) analysis::write_thermal_yaml(o.out, fit, record, config_name);
  if (!o.report.empty()) {
    io::create_output_directory(o.report);
    analysis::write_thermal_fit_json(o.report + "/fit.json", fit, record, config_name);
    analysis::write_thermal_fit_report(o.report + "/report.md", fit, record, config_name);
    analysis::write_thermal_predictions(o.report + "/predictions.csv", fit, record);
  }
  print_fit(fit, record);
  if (runaway) {
    std::printf("\n");
    std::fprintf(stderr,
                 "rpem thermal fit: %s not written: %s. rpemd and `rpem estimate --thermal` "
                 "would refuse it. Either machine.rated in %s is not this machine's rating, or the log does not "
                 "bound how the winding sheds heat (see the parameters above): a log at currents near the rated one "
                 "does\n",
                 o.out.c_str(), runaway->c_str(), config_name.c_str());
    return kExitDataError;
  }
  std::printf("; wrote %s\n", o.out.c_str());
  return kExitOk;
}

}  // namespace

Runner add_thermal_command(CLI::App& app) {
  auto opts = std::make_shared<ThermalFitCliOptions>();
  CLI::App* cmd = app.add_subcommand("thermal", "The machine's thermal network (docs/thermal.md)");
  cmd->require_subcommand(1);
  CLI::App* fit = cmd->add_subcommand("fit", "Fit the thermal network to a log and write thermal.yaml");
  add_log_options(*fit, opts->log, opts->log_map, "", LogPath::kFileOrSessions);
  fit->add_option("--config", opts->config, "machine and estimator YAML (default: built-in paper-ipmsm.yaml)")
      ->check(CLI::ExistingFile);
  writes_file(fit->add_option("--out", opts->out, "thermal.yaml to write"))->required();
  fit->add_option(
         "--start", opts->start,
         "thermal section to start from: its laws, filter settings and, if it has `nodes`, its network (topology and values)")
      ->check(CLI::ExistingFile);
  fit->add_option("--nodes", opts->nodes,
                  "without a network to start from: 2 (winding, magnet) or 3 (winding, stator_iron, magnet)")
      ->check(CLI::IsMember({2, 3}));
  CLI::Option* until = fit->add_option("--fit-until-s", opts->fit_until_s,
                                       "train on the log up to this time, judge the rest (default: 75 %; a folder's "
                                       "sessions one after another on one time axis, as the report lists them)");
  fit->add_option("--held-out-sessions", opts->held_out_sessions,
                  "a folder: judge its last N sessions, fit the ones before (instead of --fit-until-s)")
      ->check(CLI::PositiveNumber)
      ->excludes(until);
  fit->add_option("--winding-sensor-sigma-K", opts->winding_sensor_sigma_K,
                  "σ of the log's winding sensor (default: --start's winding_sensor_sigma_K, else 1 K)")
      ->check(CLI::Range(1e-3, 100.0));
  fit->add_option("--period-s", opts->period_s, "the filter's step (default: thermal.yaml's, 1 s)")
      ->check(CLI::Range(1e-3, 3600.0));
  fit->add_option("--disturbance-time-constant-s", opts->disturbance_time_constant_s,
                  "every node's heat disturbance correlation time τ_d (eq. 14.19), given instead of chosen per node by "
                  "the likelihood (1e9: the random walk)")
      ->check(CLI::Range(1.0, 1e9));
  fit->add_flag(
      "--keep-magnet-reference", opts->keep_magnet_reference,
      "keep the magnet law's psi_m_ref as given (--start or the machine's) instead of anchoring it at the soaked start");
  fit->add_option("--report", opts->report, "directory for report.md, fit.json and predictions.csv");
  return [fit, opts]() { return fit->parsed() ? run_thermal_fit(*opts) : -1; };
}

}  // namespace rpem::tools
