// rpem diagnose --log LOG.csv|FOLDER --config MACHINE.yaml --out DIR [--truth TRUTH.csv] …
// Shows what the nominal model gets wrong on measured data, names the cause from the catalogue of
// effects, extends the model and measures the gain (docs/diagnose.md). Writes DIR/report.html,
// DIR/report.md, the figures, DIR/diagnosis.json and DIR/extended.yaml — all at once at the end: they are
// written into a directory beside DIR and moved into it when complete, so that a run stopped by Ctrl-C
// (exit 130) or failing leaves DIR as it was.

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "commands.hpp"
#include "diagnose_monitor.hpp"
#include "log_options.hpp"
#include "log_sessions.hpp"
#include "machine_option.hpp"
#include "rpem/analysis/diagnose/diagnose_output.hpp"
#include "rpem/analysis/work_pool.hpp"
#include "rpem/io/errors.hpp"
#include "rpem/io/number_format.hpp"
#include "rpem/io/sample_counts.hpp"

namespace rpem::tools {
namespace {

struct DiagnoseCliOptions {
  std::string log, log_map, config, out, truth, model = "auto";
  double reference_C = analysis::DiagnoseOptions{}.reference_C;
  double switching_frequency_Hz = 0.0;
  analysis::SelectionOptions selection;
  int blocks = 40;
  int jobs = analysis::available_cpus();
};

namespace fs = std::filesystem;

/// The output files, written into a staging directory beside DIR and moved into DIR once all are there.
class StagedOutput {
 public:
  explicit StagedOutput(const std::string& out) : out_(fs::path(out).lexically_normal()) {
    if (out_.filename().empty()) out_ = out_.parent_path();
    staging_ = out_;
    staging_ += ".partial-" + std::to_string(getpid());
    std::error_code ec;
    fs::remove_all(staging_, ec);
    fs::create_directories(staging_, ec);
    if (ec) throw io::InputError(staging_.string(), 0, 0, "", "cannot create directory: " + ec.message());
  }
  ~StagedOutput() {
    std::error_code ec;
    fs::remove_all(staging_, ec);
  }
  StagedOutput(const StagedOutput&) = delete;
  StagedOutput& operator=(const StagedOutput&) = delete;

  [[nodiscard]] std::string dir() const { return staging_.string(); }
  /// Moves every file written into DIR (each one's rename replaces what DIR held under its name).
  void commit() {
    std::error_code ec;
    fs::create_directories(out_, ec);
    if (ec) throw io::InputError(out_.string(), 0, 0, "", "cannot create directory: " + ec.message());
    for (const fs::directory_entry& e : fs::directory_iterator(staging_)) {
      fs::rename(e.path(), out_ / e.path().filename(), ec);
      if (ec) throw io::InputError((out_ / e.path().filename()).string(), 0, 0, "", "cannot write: " + ec.message());
    }
  }

 private:
  fs::path out_, staging_;
};

std::string read_text(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw io::ConfigError(path, 0, 0, "", "cannot open file");
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

/// The diagnosis in brief on stdout: the baseline, the calibration, the effects found and left out, the verdict.
void print_summary(const analysis::Diagnosis& d) {
  const analysis::Selection& s = d.selection;
  std::printf("baseline (the configuration as it is): held-out residual %.4g A RMS\n", d.baseline_heldout_rms_A);
  std::printf("calibrated baseline: held-out residual %.4g A RMS", d.calibration.heldout_rms_A);
  for (std::size_t i = 0; i < analysis::kCalibrated.size(); ++i) {
    if (d.calibration.identifiable[i]) {
      std::printf(" %s=%.6g (mismatch ±%.2g %%)", analysis::kCalibrated[i], d.calibration.value[i],
                  100.0 * analysis::mismatch_half_width(d, i));
    }
  }
  std::printf("\n");
  for (const std::string& f : analysis::calibrated_despite_mismatch(d))
    std::printf("calibrated despite a large mismatch: %s\n", f.c_str());
  for (const std::string& f : analysis::calibration_findings(d)) std::printf("calibration: %s\n", f.c_str());
  if (d.least_squares) {
    std::printf(
        "outliers: %zu of %zu training samples beyond %.3g A moved the least-squares fit (%s by %.2g times its 95 %% "
        "half-width): diagnosed again under Huber's loss, b = %.3g A after %d run%s\n",
        d.outliers.test.beyond, d.outliers.test.samples, d.outliers.test.threshold_A, d.outliers.parameter.c_str(),
        d.outliers.largest_shift, d.outliers.loss.threshold_A, d.outliers.robust_runs,
        d.outliers.robust_runs == 1 ? "" : "s");
  }
  if (s.found.empty()) std::printf("effects: none\n");
  for (std::size_t j = 0; j < s.found.size(); ++j) {
    std::printf("effect %s:", s.found[j].effect.label().c_str());
    for (const analysis::NamedValue& v : analysis::found_parameters(d, j)) {
      if (v.text.empty()) {
        std::printf(" %s=%.6g", v.name.c_str(), v.value);
      } else {
        std::printf(" %s=%s", v.name.c_str(), v.text.c_str());
      }
    }
    const analysis::EstimatorCheck* c = analysis::estimator_check(d, j);
    std::printf(" (held-out gain %.1f %%%s)\n", s.found[j].gain_pct,
                c && !c->kept ? "; not in extended.yaml: the estimator predicts worse with it" : "");
  }
  for (const analysis::ImplausibleEffect& i : s.implausible) {
    std::printf("implausible, not named: %s: %s\n", i.effect.label().c_str(), i.why.reason.c_str());
  }
  for (const analysis::Unidentifiable& u : s.not_identifiable) {
    std::string names;
    for (const std::string& e : u.effects) names += (names.empty() ? "" : " / ") + e;
    std::printf("not identifiable: %s\n", names.c_str());
  }
  std::printf("extended model: held-out residual %.4g A RMS\n", s.extended_heldout_rms_A);
  if (d.verdict.ratio) {
    std::printf("verdict: %s (%.3g times the noise floor of %.3g A)\n", analysis::to_string(d.verdict.kind),
                *d.verdict.ratio, d.verdict.noise_floor_A.value_or(0.0));
  } else {
    std::printf("verdict: %s (noise floor unknown)\n", analysis::to_string(d.verdict.kind));
  }
  for (const std::string& f : d.verdict.findings) std::printf("  %s\n", f.c_str());
}

/// What the blocks' time leaves out (the log's pauses), and any block that holds no sample all the same: the fits
/// and the held-out test rest on the blocks that hold samples, which a user should know before reading the verdict.
/// "" where the log does not pause and every block holds samples.
std::string blocks_note(const analysis::LogData& log) {
  int empty = 0;
  for (int b = 0; b < log.blocks; ++b) {
    empty += log.block_first[static_cast<std::size_t>(b)] == log.block_first[static_cast<std::size_t>(b) + 1] ? 1 : 0;
  }
  std::string note;
  char text[320];
  if (log.pauses > 0) {
    std::snprintf(text, sizeof text,
                  "the log's time pauses %zu time%s (the longest %.6g s; a pause: an interval over %g times the median "
                  "one, %.6g s): the %d training and held-out blocks are equal in the time it sampled, the pauses left out",
                  log.pauses, log.pauses == 1 ? "" : "s", log.longest_pause_s, analysis::LogData::kPauseMedianIntervals,
                  log.median_dt_s, log.blocks);
    note = text;
  }
  if (empty > 0) {
    std::snprintf(text, sizeof text,
                  "%s%d of the %d training and held-out blocks hold no sample: the fits and the held-out test rest on the "
                  "other blocks",
                  note.empty() ? "" : "; ", empty, log.blocks);
    note += text;
  }
  return note;
}

int diagnose_and_write(const DiagnoseCliOptions& o, const io::MachineConfig& config, const std::string& config_text,
                       const std::string& config_name, const analysis::LogOptions& log_options, TerminalMonitor& monitor);

int run_diagnose(const DiagnoseCliOptions& o) {
  if (!o.truth.empty() && fs::is_directory(o.log)) {
    std::fprintf(stderr, "rpem diagnose: --truth is one log's truth: with --log a folder, give none\n");
    return kExitUsage;
  }
  const std::string config_text = o.config.empty() ? io::builtin_paper_config_text() : read_text(o.config);
  const io::MachineConfig config = machine_config_or_builtin(o.config, "rpem diagnose");
  const std::string config_name = o.config.empty() ? "builtin:paper-ipmsm" : o.config;

  analysis::LogOptions log_options = analysis::log_options(config);
  log_options.blocks = o.blocks;
  log_options.log_map = o.log_map;
  if (o.model != "auto") {
    log_options.mode = o.model == "transient" ? analysis::ModelMode::kTransient : analysis::ModelMode::kSteadyState;
  }
  TerminalMonitor monitor;
  try {
    return diagnose_and_write(o, config, config_text, config_name, log_options, monitor);
  } catch (const analysis::Interrupted&) {
    monitor.finish();
    std::fprintf(stderr, "rpem diagnose: interrupted; %s left as it was\n", o.out.c_str());
    return io::kExitInterrupted;
  }
}

int diagnose_and_write(const DiagnoseCliOptions& o, const io::MachineConfig& config, const std::string& config_text,
                       const std::string& config_name, const analysis::LogOptions& log_options, TerminalMonitor& monitor) {
  std::fprintf(stderr, "rpem diagnose: reading %s\n", o.log.c_str());
  const auto progress = [&](std::uint64_t done, std::uint64_t total) {
    monitor.reading(done, total);
    if (monitor.stop_requested()) throw analysis::Interrupted();
  };
  analysis::LogData log = load_log_or_sessions(o.log, config.machine, log_options, progress);
  monitor.finish();
  print_log_read("rpem diagnose", log);
  io::check_log_supports(config, config_name, log.layout.u_dc, o.log);
  if (const std::string note = blocks_note(log); !note.empty()) {
    std::fprintf(stderr, "rpem diagnose: note: %s\n", note.c_str());
  }
  const double judged_from_s = log.t_start_s + analysis::kJudgedFromFraction * (log.t_end_s - log.t_start_s);
  const analysis::ParameterTrack truth =
      o.truth.empty() ? analysis::ParameterTrack{} : analysis::load_truth(o.truth, judged_from_s, log.t_end_s);

  analysis::DiagnoseOptions options;
  options.reference_C = o.reference_C;
  options.switching_frequency_Hz = o.switching_frequency_Hz;
  options.selection = o.selection;
  options.jobs = o.jobs;
  options.monitor = &monitor;
  std::fprintf(stderr, "rpem diagnose: %zu samples, %s model; fitting the catalogue's effects (%d jobs)\n", log.size(),
               analysis::to_string(log.mode), o.jobs);
  const analysis::Diagnosis d = analysis::diagnose(std::move(log), config, options, truth);
  monitor.finish();
  std::fprintf(stderr, "rpem diagnose: %s\n", io::regime_summary(d.regimes.counts).c_str());
  for (const std::string& why : d.regimes.explanations) std::fprintf(stderr, "rpem diagnose: %s\n", why.c_str());
  if (const std::string note = io::assumed_frame_note(d.regimes.counts); !note.empty())
    std::fprintf(stderr, "rpem diagnose: note: %s\n", note.c_str());

  StagedOutput staged(o.out);
  try {
    analysis::write_diagnosis_json(staged.dir() + "/diagnosis.json", d, config_name);
    analysis::write_extended_yaml(staged.dir() + "/extended.yaml", d, config_text);
    analysis::write_diagnose_report(staged.dir(), d, config_name);
  } catch (const std::exception&) {
    if (monitor.stop_requested()) throw analysis::Interrupted();  // gnuplot, stopped by the same Ctrl-C
    throw;
  }
  // A Ctrl-C while the figures were drawn stopped gnuplot too: what was written may be incomplete.
  if (monitor.stop_requested()) throw analysis::Interrupted();
  staged.commit();

  print_summary(d);
  std::printf("wrote %s/report.html, report.md, diagnosis.json, extended.yaml (%.2f s)\n", o.out.c_str(), d.elapsed_s);
  return kExitOk;
}

}  // namespace

Runner add_diagnose_command(CLI::App& app) {
  auto o = std::make_shared<DiagnoseCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "diagnose", "Show what the model gets wrong on measured data, name the cause, extend the model, measure the gain");
  add_log_options(*cmd, o->log, o->log_map, "", LogPath::kFileOrSessions);
  cmd->add_option("--config", o->config,
                  "machine configuration YAML, the baseline: its whole model, extensions and drift laws (default: built-in "
                  "paper-ipmsm); an extended.yaml of another recording is one")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", o->out, "directory for report.html, report.md, figures, diagnosis.json, extended.yaml")
      ->required();
  cmd->add_option("--truth", o->truth,
                  "true parameters (columns t, psi_m, r_s; others ignored) to judge the estimates against, e.g. "
                  "rpem sim --truth or --vesc-tool-truth")
      ->check(CLI::ExistingFile);
  cmd->add_option("--model", o->model, "replay model: auto (from the sample interval), transient, steady_state")
      ->check(CLI::IsMember({"auto", "transient", "steady_state"}));
  std::string reference_help = "temperature to which found drift laws are referred (default ";
  io::append_number(reference_help, o->reference_C);
  cmd->add_option("--reference-temperature-C", o->reference_C, reference_help + ")");
  cmd->add_option("--switching-frequency-Hz", o->switching_frequency_Hz,
                  "PWM frequency, to report dead time in seconds (default: model_extensions.deadtime's)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--min-gain-pct", o->selection.min_gain_pct, "held-out RMS gain an effect must bring [%] (default 2)")
      ->check(CLI::Range(0.0, 100.0));
  cmd->add_option("--max-p", o->selection.max_p, "largest signed-rank p over the held-out blocks (default 0.01)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--blocks", o->blocks, "training + held-out blocks (default 40)")->check(CLI::Range(4, 1000));
  cmd->add_option("--jobs,--threads", o->jobs,
                  "threads that replay the log's blocks and fit the candidates (default: the CPUs this process may use, " +
                      std::to_string(o->jobs) + " here); the results are the same for any number")
      ->check(CLI::Range(1, 256));
  return [cmd, o]() { return cmd->parsed() ? run_diagnose(*o) : -1; };
}

}  // namespace rpem::tools
