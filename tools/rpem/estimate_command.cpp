// rpem estimate --log LOG.csv|FOLDER [--log-map MAP.yaml] --config CFG.yaml --out EST.csv|DIR
//              [--algorithm sga|gna|phyint] [--every N | --rate HZ] [--thermal THERMAL.yaml]
// Runs the estimator offline over a drive log, exactly as rpemd would run it online: a log of instantaneous
// samples through DriveEstimator, a log of averaged samples (our averaged log, VESC Tool's realtime log, a
// map of averaged samples; docs/drive-log.md) through AveragedDriveEstimator. With --thermal, the thermal
// network's filter runs beside it as in rpemd (core::ThermalFusion, docs/thermal.md) and the estimate CSV
// gains the fused temperatures. A folder of logs: each log on its own, as if it were the only one (log_folder.hpp).

#include <algorithm>
#include <array>
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
#include "one_window.hpp"
#include "option_checks.hpp"
#include "progress.hpp"
#include "rpem/analysis/rs_along_current.hpp"
#include "rpem/core/averaged_estimator.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/units.hpp"
#include "rpem/io/averaged_log.hpp"
#include "rpem/io/drive_log.hpp"
#include "rpem/io/estimate_log.hpp"
#include "rpem/io/flux_reading.hpp"
#include "rpem/io/log_source.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/io/rotor_frame_rebuild.hpp"
#include "rpem/io/sample_counts.hpp"
#include "rpem/io/thermal_config.hpp"

namespace rpem::tools {
namespace {

struct EstimateOptions {
  std::string log;
  std::string log_map;
  std::string config;
  std::string out;
  std::string algorithm;
  std::string thermal;
  long every = 1;
  double rate_Hz = 0.0;
};

/// Which estimates --out gets (docs/drive-log.md, "Estimate CSV"): every N-th sample (--every), or the first
/// sample at or after each point of a grid 1/rate apart in the log's time, from its first sample (--rate; a
/// gap in the log skips the grid's points inside it).
class Decimation {
 public:
  explicit Decimation(const EstimateOptions& o)
      : every_(static_cast<std::uint64_t>(o.every)), period_ns_(o.rate_Hz > 0.0 ? std::llround(1e9 / o.rate_Hz) : 0) {}
  /// Whether the estimate of the sample at t_ns is written.
  bool take(std::int64_t t_ns) {
    if (period_ns_ <= 0) return seen_++ % every_ == 0;
    if (seen_++ > 0 && t_ns < next_ns_) return false;
    next_ns_ = seen_ == 1 ? t_ns + period_ns_ : next_ns_ + period_ns_;
    if (next_ns_ <= t_ns) next_ns_ = t_ns + period_ns_;  // across a gap: the grid starts again here
    return true;
  }

 private:
  std::uint64_t every_, seen_ = 0;
  std::int64_t period_ns_;
  std::int64_t next_ns_ = 0;  ///< the grid's next point (--rate), once a sample was seen
};

/// The thermal filter beside the estimator, when --thermal is given.
class ThermalRun {
 public:
  ThermalRun(const EstimateOptions& o, const io::MachineConfig& cfg, const core::PerUnitBase& base) {
    if (o.thermal.empty()) return;
    const io::ThermalConfig t = io::load_thermal_config(o.thermal, cfg);
    for (int i = 0; i < t.fusion.filter.network.nodes; ++i) names_.push_back(t.node_names[static_cast<std::size_t>(i)]);
    for (const std::string& note : io::assumed_law_notes(t, true))
      std::fprintf(stderr, "rpem estimate: thermal: note: %s\n", note.c_str());
    if (const std::optional<std::string> note = io::process_noise_note(t))
      std::fprintf(stderr, "rpem estimate: thermal: note: %s\n", note->c_str());
    coolant_C_ = t.fusion.coolant_C;
    sensor_fused_ = t.fusion.winding_sensor_sigma_K > 0.0;
    fusion_.emplace(t.fusion, base, cfg.machine);
  }
  [[nodiscard]] const std::vector<std::string>& node_names() const { return names_; }
  /// The sample's temperatures; `t_ns` its time (the interval since the previous sample is the time it stands for).
  void step(const core::Estimate& e, std::int64_t t_ns, double coolant_C, double winding_C) {
    if (!fusion_) return;
    core::ThermalSample s;
    s.dt_s = previous_ns_ ? 1e-9 * static_cast<double>(t_ns - *previous_ns_) : 0.0;
    s.coolant_C = coolant_C;
    s.winding_sensor_C = winding_C;
    ++samples_;
    if (!std::isnan(coolant_C)) {
      coolant_read_ = true;
    } else if (coolant_read_) {
      ++coolant_held_;
    } else {
      ++without_coolant_;
    }
    previous_ns_ = t_ns;
    fusion_->step(e, s);
    const core::ThermalEstimate& now = fusion_->estimate();
    if (!now.started) return;
    for (auto [node, peak] : {std::pair{now.magnet, &magnet_}, std::pair{now.winding, &winding_}}) {
      const core::ThermalNodeReport r = core::report_node(now, node, t_ns);
      peak->add(r.t_C, r.sd_K);
    }
  }
  [[nodiscard]] const core::ThermalEstimate* estimate() const { return fusion_ ? &fusion_->estimate() : nullptr; }
  /// On stderr: the winding readings refused as a held value (thermal_held_reading.hpp), where there were any.
  void explain() const {
    if (!fusion_) return;
    if (without_coolant_ > 0) {
      std::fprintf(
          stderr,
          "rpem estimate: thermal: %llu of %llu samples have no coolant temperature (no T_coolant column, or "
          "no reading in their cell) and none before them: the coolant is taken as %.4g °C there (thermal.coolant_C); a "
          "coolant that moves shows as a model error (docs/thermal.md)\n",
          static_cast<unsigned long long>(without_coolant_), static_cast<unsigned long long>(samples_), coolant_C_);
    }
    if (coolant_held_ > 0) {
      std::fprintf(stderr,
                   "rpem estimate: thermal: %llu of %llu samples have no coolant reading after one: the newest reading "
                   "holds there, and the fused band widens over each filter step without a reading as an unread "
                   "coolant may move (thermal.coolant_drift_K2_per_s: %.3g K²/s%s; eq. 14.29)\n",
                   static_cast<unsigned long long>(coolant_held_), static_cast<unsigned long long>(samples_),
                   fusion_->config().filter.coolant_drift_K2_per_s,
                   fusion_->config().filter.coolant_drift_K2_per_s > 0.0 ? "" : ", so it does not widen");
    }
    if (fusion_->estimate().start_assumed_soaked) {
      // core::start_temperatures_C: without a fused winding reading at the start, the soak is assumed.
      const std::string note = io::soaked_start_note(
          std::string("the log gives no ") +
          (sensor_fused_ ? "winding reading"
                         : "winding reading the filter fuses (the thermal section has no winding_sensor)") +
          " at its start to test it");
      std::fprintf(stderr, "rpem estimate: thermal: note: %s\n", note.c_str());
    }
    if (fusion_->estimate().winding_readings_held == 0) return;
    std::fprintf(stderr,
                 "rpem estimate: thermal: the winding sensor's reading was refused as a held value in %lld filter "
                 "steps: it stayed on one value while the network says the winding moved by more than the filter's "
                 "gate, or while the gate refused it (docs/thermal.md, \"A winding reading that holds one value\"); "
                 "the fused winding is predicted there\n",
                 static_cast<long long>(fusion_->estimate().winding_readings_held));
  }
  /// The fused temperatures' peaks so far, as the estimate CSV reports them at each sample.
  [[nodiscard]] const TemperaturePeak& magnet_peak() const { return magnet_; }
  [[nodiscard]] const TemperaturePeak& winding_peak() const { return winding_; }

 private:
  TemperaturePeak magnet_, winding_;
  std::vector<std::string> names_;
  std::optional<core::ThermalFusion> fusion_;
  std::optional<std::int64_t> previous_ns_;
  /// Samples the filter was given; those without a coolant reading before the first one, and after it (held).
  std::uint64_t samples_ = 0, without_coolant_ = 0, coolant_held_ = 0;
  bool coolant_read_ = false;
  double coolant_C_ = 0.0;     ///< what the filter takes for a coolant before its first reading
  bool sensor_fused_ = false;  ///< a winding reading is fused (its σ given)
};

/// What the run did, for its summary on stderr (and a folder's summary.csv): the last estimate and the samples per
/// regime.
struct Tally {
  io::SampleCounts counts;
  core::Estimate last;
  std::optional<std::int64_t> first_t_ns;
  std::array<std::uint64_t, 2> adapted{};           ///< samples in which ψm, R_s adapted
  std::array<std::optional<bool>, 2> identifiable;  ///< ψm, R_s: check_identifiable's verdict, where it ran
  TemperaturePeak magnet, winding;                  ///< with --thermal
  void take_peaks(const ThermalRun& t) {
    magnet = t.magnet_peak();
    winding = t.winding_peak();
  }
  /// The windows R_s adapted on, where each leaves the drop along its current (analysis::RsReading).
  std::vector<analysis::RsReading> rs_readings;
  /// Per parameter (ψm, R_s), each window it adapted on and the step it took there (window_that_decides).
  std::array<std::vector<AdaptationStep>, 2> steps;
  void count(const core::Estimate& e) {
    const bool has_previous = first_t_ns.has_value();
    if (!first_t_ns) first_t_ns = e.t_ns;
    std::array<double, 2> before{last.psi_m_Wb, last.r_s_Ohm};
    if (e.retracted_previous) uncount_adaptation(last, &before);  // a window found mixed: what it adapted was taken back
    last_read_rs_ = has_previous && active(e, 1) && read_rs(last.r_s_Ohm, e);
    const std::array<double, 2> now{e.psi_m_Wb, e.r_s_Ohm};
    for (std::size_t k = 0; k < steps.size(); ++k) {
      if (has_previous && active(e, k)) steps[k].push_back({samples_seen_, now[k] - before[k]});
      adapted[k] += active(e, k) ? 1 : 0;
    }
    ++samples_seen_;
    last = e;
    counts.add(e);
  }
  /// Takes back `e`'s adaptations: `e` is `last`, whose reading and steps (if any) are the newest. `before`, if given,
  /// becomes the estimates before `e`.
  void uncount_adaptation(const core::Estimate& e, std::array<double, 2>* before = nullptr) {
    for (std::size_t k = 0; k < steps.size(); ++k) {
      if (!active(e, k)) continue;
      --adapted[k];
      if (steps[k].empty() || steps[k].back().index + 1 != samples_seen_) continue;  // the log's first sample
      if (before != nullptr) (*before)[k] -= steps[k].back().change;
      steps[k].pop_back();
    }
    if (last_read_rs_) rs_readings.pop_back();
    last_read_rs_ = false;
  }
  /// The log's end ends the last chain: its newest window, never judged, is retracted (docs/derivations.md §13,
  /// "Mixed windows"); the final estimates are the estimator's, and the windows so left out are said.
  void end_chain(core::AveragedDriveEstimator& estimator) {
    if (estimator.end_chain()) uncount_adaptation(last);
    last.psi_m_Wb = estimator.psi_m_Wb();
    last.r_s_Ohm = estimator.r_s_Ohm();
    if (const std::uint64_t n = estimator.unjudged_windows(); n > 0) {
      std::fprintf(stderr,
                   "rpem estimate: %llu window%s ending a chain (before a gap or at the log's end) left out of the "
                   "estimates: a bridge release inside a window shows only in the next one (docs/derivations.md §13, "
                   "\"Mixed windows\")\n",
                   static_cast<unsigned long long>(n), n == 1 ? "" : "s");
    }
  }
  /// `kind`: the sample's noun, singular ("sample").
  [[nodiscard]] std::string summary(core::Algorithm a, const char* kind) const {
    char text[256];
    std::snprintf(text, sizeof text, "%llu %s%s, psi_m = %.6g Wb, r_s = %.6g Ohm (%s), %llu resync%s",
                  static_cast<unsigned long long>(counts.samples), kind, counts.samples == 1 ? "" : "s", last.psi_m_Wb,
                  last.r_s_Ohm, io::to_string(a), static_cast<unsigned long long>(counts.resyncs),
                  counts.resyncs == 1 ? "" : "s");
    return text;
  }
  /// The regimes' counts, and why, where more than a tenth of the samples adapted nothing (and where R_s adapted
  /// only on an assumed frame).
  void explain() const {
    std::fprintf(stderr, "rpem estimate: %s\n", io::regime_summary(counts).c_str());
    for (const std::string& why : io::exclusion_explanations(counts))
      std::fprintf(stderr, "rpem estimate: %s\n", why.c_str());
    if (const std::string note = io::assumed_frame_note(counts); !note.empty())
      std::fprintf(stderr, "rpem estimate: note: %s\n", note.c_str());
  }

 private:
  bool last_read_rs_ = false;  ///< `last` left a reading in rs_readings
  std::size_t samples_seen_ = 0;
  static bool active(const core::Estimate& e, std::size_t k) {
    return (e.detail.flags & (k == 0 ? core::step_flag::kPsiMActive : core::step_flag::kRsActive)) != 0;
  }
  /// The drop along the current the model leaves at a window R_s adapted on (eq. 12.1): î is predicted with the
  /// r̂s before the window, î = e/r̂s where ω·L ≪ r̂s (the speeds R_s adapts at), so y = r̂s·(î·i)/|i|.
  bool read_rs(double r_before_Ohm, const core::Estimate& e) {
    const double current_A = e.i_meas_A.norm();
    if (!(current_A > 0.0)) return false;
    rs_readings.push_back({core::to_seconds(e.t_ns), current_A, r_before_Ohm * e.i_hat_A.dot(e.i_meas_A) / current_A});
    return true;
  }
};

/// Whether the log determines each parameter (docs/drive-log.md, "Identifiable"): the estimator run again
/// from each end of D_M for one parameter (the other from its start). Half the spread of the two results
/// is how much of the estimate its start still decides; beyond the accuracy asked of the parameter (issue
/// 23: ψm 2 %, R_s 5 % — the same 2 % that sets angle_tolerance_rad) the log does not identify it.
struct Identifiability {
  const char* name;
  const char* unit;
  double tolerance;  ///< relative
  double lo, hi;     ///< D_M's ends
  double from_lo = 0.0, from_hi = 0.0;
};

/// How often parameter k (0: ψm, 1: R_s) adapted against how often a sample excited it, and what else keeps it from
/// adapting where it is excited: the gain schedule's speed limit (its key and value), outliers, a resync's restart.
std::string adapted_clause(std::size_t k, const core::RegimeCounts& regimes, std::uint64_t adapted,
                           const core::EstimatorSettings& e) {
  const auto n = [&](core::Regime r) { return regimes.n[static_cast<std::size_t>(r)]; };
  const std::uint64_t excited =
      n(core::Regime::kExcitesBoth) + n(k == 0 ? core::Regime::kExcitesPsiM : core::Regime::kExcitesRs);
  char text[400];
  std::snprintf(text, sizeof text,
                "it adapted on %llu of the %llu samples that excite it; the others: outside the gain schedule (%s adapts "
                "only %s estimator.scheduler.%s, %.4g rpm), outliers, or a resync's restart. The regimes above say why "
                "the rest did not excite it",
                static_cast<unsigned long long>(adapted), static_cast<unsigned long long>(excited), k == 0 ? "psi_m" : "r_s",
                k == 0 ? "above" : "below", k == 0 ? "psi_m_min_speed_rpm" : "r_s_max_speed_rpm",
                k == 0 ? e.psi_m_min_speed_rpm : e.r_s_max_speed_rpm);
  return text;
}

/// Whether each parameter's last estimate lies on an end of D_M (estimator.bounds), where the projection holds it;
/// says so on stderr for each that does: the machine's value may lie beyond, and the value is no identification.
std::array<bool, 2> say_estimates_at_bounds(const core::Estimate& last, const core::EstimatorSettings& e) {
  struct Bound {
    const char* name;
    const char* key;
    const char* unit;
    double value, lo, hi;
  };
  const std::array<Bound, 2> b{{{"psi_m", "psi_m_Wb", "Wb", last.psi_m_Wb, e.psi_m_min_Wb, e.psi_m_max_Wb},
                                {"r_s", "r_s_Ohm", "Ohm", last.r_s_Ohm, e.r_s_min_Ohm, e.r_s_max_Ohm}}};
  std::array<bool, 2> at{};
  for (std::size_t k = 0; k < b.size(); ++k) {
    constexpr double kRounding = 1e-9;  // the projection is onto D_M in pu: back in SI it rounds
    const bool low = b[k].value <= b[k].lo * (1.0 + kRounding), high = b[k].value >= b[k].hi * (1.0 - kRounding);
    at[k] = low || high;
    if (!at[k]) continue;
    std::fprintf(stderr,
                 "rpem estimate: %s ended at its %s bound %.5g %s (estimator.bounds.%s: [%.5g, %.5g]), where the "
                 "estimator holds it: the machine's value may lie beyond it, so %.5g %s is no identification; if the "
                 "machine can have such a value, widen the bound (docs/configuration.md)\n",
                 b[k].name, low ? "lower" : "upper", low ? b[k].lo : b[k].hi, b[k].unit, b[k].key, b[k].lo, b[k].hi,
                 b[k].value, b[k].unit);
  }
  return at;
}

/// Whether the windows R_s adapted on imply the resistance it ends at (eq. 12.1): where their drop along the current
/// is R·|i| + V with a V the model leaves out, every start agrees on R + V/|i|, which the runs from the bounds
/// cannot see. R at the last window differing from r̂s by more than the accuracy asked and z of its standard errors
/// (`significance_sigma`) is said, and the estimate is no identification.
bool check_rs_along_current(const std::vector<analysis::RsReading>& readings, double r_s_Ohm, double tolerance,
                            const core::EstimatorSettings& e) {
  const std::optional<analysis::RsAlongCurrent> fit = analysis::fit_rs_along_current(readings);
  if (!fit) return true;
  const double difference_Ohm = r_s_Ohm - fit->r_at_last_Ohm;
  const double z = e.regimes.significance_sigma;
  if (!(std::abs(difference_Ohm) > std::max(tolerance * r_s_Ohm, z * fit->r_at_last_se_Ohm))) return true;
  std::fprintf(stderr,
               "rpem estimate: r_s not identifiable from this log: the %zu windows it adapted on (%.3g to %.3g A) read "
               "their drop along the current as R·|i| + V with V = %.3g V (+-%.2g V) and R = %.5g Ohm (+-%.2g) at the "
               "last of them, %+.0f %% from the %.5g Ohm the estimator ends at (%.1f standard errors): "
               "a voltage the model leaves out along the current reads R_s as R + V/|i| from every start: a sensorless "
               "drive's stall, where the rotor moves while the frame is not the rotor's and its back EMF falls along the "
               "current, or an inverter's dead time the drive does not fully compensate (model_extensions.deadtime). "
               "rpem diagnose shows the error; standstill with the rotor held at two or more currents tells R from V "
               "(docs/drive-log.md, \"A voltage along the current\")\n",
               fit->readings, fit->current_min_A, fit->current_max_A, fit->v_V, fit->v_se_V, fit->r_at_last_Ohm,
               fit->r_at_last_se_Ohm, 100.0 * (r_s_Ohm / fit->r_at_last_Ohm - 1.0), r_s_Ohm,
               std::abs(difference_Ohm) / fit->r_at_last_se_Ohm);
  return false;
}

/// Whether the estimate rests on one window (docs/drive-log.md, "One window decides"): said, with the window, where
/// taking out the step one window took moves the end by more than the accuracy asked. Every start agrees on such an
/// estimate, so the runs from the bounds cannot see it; whether that one window's model holds (a stall's onset, a
/// transient the classifier did not see) nothing else in the log confirms.
bool check_one_window(const std::vector<core::AveragedSample>& samples, const io::MachineConfig& cfg, std::size_t k,
                      const std::vector<AdaptationStep>& steps, double estimate, double tolerance, const char* name,
                      const char* unit) {
  const std::optional<DecidingWindow> w = window_that_decides(samples, cfg, k, steps, estimate, tolerance);
  if (!w) return true;
  const core::AveragedSample& a = samples[w->index];
  std::fprintf(stderr,
               "rpem estimate: %s not identifiable from this log: one window decides it: the window ending at t = %.3f s "
               "(the estimate CSV's t; %.0f erpm, %.3g A) moved it by %+.1f %%, and without that step the estimator ends "
               "at %.5g %s, %+.1f %% from the %.5g %s it ends at, more than the %.0f %% asked of it; no other window "
               "confirms that one's model (a sensorless drive's stall or its onset, a transient inside the window): "
               "rpem diagnose shows the window (docs/drive-log.md, \"One window decides\")\n",
               name, core::to_seconds(a.t_ns), core::rad_s_to_rpm(a.omega_el_rad_s), a.i_dq_A.norm(),
               100.0 * w->change / estimate, w->without, unit, 100.0 * (w->without / estimate - 1.0), estimate, unit,
               100.0 * tolerance);
  return false;
}

std::array<std::optional<bool>, 2> check_identifiable(
    const std::vector<core::AveragedSample>& samples, const io::MachineConfig& cfg, const core::Estimate& last,
    const std::array<std::uint64_t, 2>& adapted, const core::RegimeCounts& regimes, const io::RotorFrameRebuild& rebuilt,
    const std::vector<analysis::RsReading>& rs_readings, const std::array<std::vector<AdaptationStep>, 2>& steps) {
  const core::EstimatorSettings& e = cfg.estimator;
  std::array<std::optional<bool>, 2> identifiable;
  const bool r_s_declared = rebuilt.voltages && e.regimes.sensorless;
  if (r_s_declared) {
    // A magnitude carries no back EMF's direction: nothing rules out the open-loop frame where R_s is excited.
    std::fprintf(stderr,
                 "rpem estimate: r_s not identifiable from this log: its voltages are rebuilt from the duty cycle's "
                 "magnitude, which carries no back-EMF direction, so the angle-lock test cannot exclude a sensorless "
                 "drive's open-loop start-ups, where R_s is excited (docs/drive-log.md, \"Logs without d/q values\"); "
                 "%.5g Ohm is not an identification\n",
                 last.r_s_Ohm);
  }
  // R_s excited where only the assumption that the frame is a sensor's made it so (io::assumed_frame_note, said
  // above): how well the log determines it says nothing of whether that assumption holds.
  const bool r_s_on_assumed_frame = !r_s_declared && regimes.r_s_on_assumed_frame > 0;
  if (r_s_on_assumed_frame) {
    std::fprintf(stderr,
                 "rpem estimate: r_s not identifiable from this log as configured: %llu of the samples that excited it "
                 "did so only if the drive's dq frame is a position sensor's, which the configuration does not say "
                 "(the note above); %.5g Ohm is no identification until estimator.regimes.angle_source says where the "
                 "frame comes from\n",
                 static_cast<unsigned long long>(regimes.r_s_on_assumed_frame), last.r_s_Ohm);
  }
  const bool r_s_excluded = r_s_declared || r_s_on_assumed_frame;
  std::array<Identifiability, 2> p{
      {{"psi_m", "Wb", 0.02, e.psi_m_min_Wb, e.psi_m_max_Wb}, {"r_s", "Ohm", 0.05, e.r_s_min_Ohm, e.r_s_max_Ohm}}};
  const std::array<double, 2> estimate{last.psi_m_Wb, last.r_s_Ohm};
  const std::array<bool, 2> at_bound = say_estimates_at_bounds(last, e);
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (at_bound[k]) {  // said above; where it ends is the bound's, not the log's
      identifiable[k] = false;
      continue;
    }
    for (const bool high : {false, true}) {
      core::EstimatorSettings s = e;
      (k == 0 ? s.initial_psi_m_Wb : s.initial_r_s_Ohm) = high ? p[k].hi : p[k].lo;
      (high ? p[k].from_hi : p[k].from_lo) = estimate_at_end(samples, cfg.machine, s, k);
    }
    const double half = 0.5 * std::abs(p[k].from_hi - p[k].from_lo) / std::abs(estimate[k]);
    identifiable[k] = half <= p[k].tolerance && !(k == 1 && r_s_excluded);
    if (*identifiable[k])
      identifiable[k] = check_one_window(samples, cfg, k, steps[k], estimate[k], p[k].tolerance, p[k].name, p[k].unit);
    if (half <= p[k].tolerance || (k == 1 && r_s_excluded)) continue;
    std::fprintf(
        stderr,
        "rpem estimate: %s not identifiable from this log: started at the ends of its bounds (%.5g, %.5g %s) "
        "the estimator ends at %.5g and %.5g %s: its start still decides +-%.0f %% of %.5g %s, more than the %.0f %% "
        "asked of it (%s)\n",
        p[k].name, p[k].lo, p[k].hi, p[k].unit, p[k].from_lo, p[k].from_hi, p[k].unit, 100.0 * half, estimate[k], p[k].unit,
        100.0 * p[k].tolerance, adapted_clause(k, regimes, adapted[k], e).c_str());
  }
  if (identifiable[1].value_or(false) && !check_rs_along_current(rs_readings, last.r_s_Ohm, p[1].tolerance, e))
    identifiable[1] = false;
  return identifiable;
}

/// One log through AveragedDriveEstimator, its estimates to `out`.
Tally run_averaged(const EstimateOptions& o, const std::string& log, const std::string& out, const io::LogSource& source,
                   const io::MachineConfig& config, const std::string& config_name) {
  io::AveragedLogRead read;
  std::vector<core::AveragedSample> samples = io::read_averaged_log(log, source.map, io::log_limits(config), &read);
  std::fprintf(stderr, "rpem estimate: %s\n", io::describe(source, read).c_str());
  const io::RotorFrameRebuild rebuilt =
      io::complete_rotor_frame(samples, read, config.machine, io::command_hold_s(config.estimator), log);
  if (rebuilt.any()) std::fprintf(stderr, "rpem estimate: %s\n", rebuilt.describe().c_str());
  if (const auto note = io::flux_mismatch_note(io::flux_reading(samples, config), config))
    std::fprintf(stderr, "rpem estimate: note: %s\n", note->c_str());
  io::check_averaged_supports(config, config_name, read.layout.u_dc, log);
  io::MachineConfig cfg = config;
  cfg.estimator = io::estimator_settings(config, rebuilt);
  core::AveragedDriveEstimator estimator(cfg.machine, cfg.estimator);
  ThermalRun thermal(o, cfg, estimator.base());
  io::EstimateLogWriter writer(out, thermal.node_names());
  Tally tally;
  tally.counts.averaged = true;
  Decimation decimation(o);
  for (const core::AveragedSample& s : samples) {
    const core::Estimate e = estimator.step(s);
    thermal.step(e, s.t_ns, s.t_coolant_C, s.t_winding_C);
    if (decimation.take(e.t_ns)) writer.write(e, estimator.core(), thermal.estimate());
    tally.count(e);
  }
  tally.end_chain(estimator);
  std::fprintf(stderr, "rpem estimate: %s\n", tally.summary(cfg.estimator.algorithm, "averaged sample").c_str());
  tally.explain();
  if (!samples.empty())
    tally.identifiable = check_identifiable(samples, cfg, tally.last, tally.adapted, tally.counts.regimes, rebuilt,
                                            tally.rs_readings, tally.steps);
  thermal.explain();
  tally.take_peaks(thermal);
  return tally;
}

/// One log through DriveEstimator, its estimates to `out`.
Tally run_instantaneous(const EstimateOptions& o, const std::string& log, const std::string& out,
                        const io::LogSource& source, const io::MachineConfig& cfg, const std::string& config_name) {
  io::DriveLogReader reader(log, source.map, io::machine_limits(cfg.machine));
  if (!source.map.columns_optional)
    std::fprintf(stderr, "rpem estimate: reading %s as %s\n", log.c_str(), source.format.c_str());
  io::check_log_supports(cfg, config_name, reader.layout().u_dc, log);
  core::DriveEstimator estimator(cfg.machine, cfg.estimator);
  ThermalRun thermal(o, cfg, estimator.base());
  io::EstimateLogWriter writer(out, thermal.node_names());
  Progress progress("rpem estimate");

  io::DriveLogRow row;
  Tally tally;
  Decimation decimation(o);
  while (reader.next(row)) {
    const core::Estimate e = estimator.step(row.sample);
    thermal.step(e, row.sample.t_ns, row.sample.t_coolant_C, row.sample.t_winding_C);
    if (decimation.take(e.t_ns)) writer.write(e, estimator, thermal.estimate());
    tally.count(e);
    if ((tally.counts.samples & 0xFFF) == 0) progress.update(reader.bytes_read(), reader.bytes_total());
  }
  progress.finish(tally.summary(cfg.estimator.algorithm, "sample") + io::describe(reader.reader().repairs()));
  tally.explain();
  if (tally.first_t_ns) {
    const std::array<bool, 2> at_bound = say_estimates_at_bounds(tally.last, cfg.estimator);
    for (std::size_t k = 0; k < at_bound.size(); ++k) {
      if (at_bound[k]) tally.identifiable[k] = false;
    }
  }
  thermal.explain();
  tally.take_peaks(thermal);
  return tally;
}

Tally run_log(const EstimateOptions& o, const std::string& log, const std::string& out, const io::MachineConfig& cfg,
              const std::string& config_name) {
  const io::LogSource source = io::log_source(log, o.log_map);
  return source.averaged() ? run_averaged(o, log, out, source, cfg, config_name)
                           : run_instantaneous(o, log, out, source, cfg, config_name);
}

LogOutcome outcome_of(const Tally& t) {
  LogOutcome o;
  o.kind = t.counts.averaged ? "averaged" : "instantaneous";
  o.samples = t.counts.samples;
  o.resyncs = t.counts.resyncs;
  o.outliers = t.counts.outliers;
  o.excluded = t.counts.regimes.excluded();
  o.adapted = t.adapted;
  o.identifiable = t.identifiable;
  o.magnet = t.magnet;
  o.winding = t.winding;
  if (t.first_t_ns) {
    o.t_first_s = core::to_seconds(*t.first_t_ns);
    o.t_last_s = core::to_seconds(t.last.t_ns);
    o.psi_m_Wb = t.last.psi_m_Wb;
    o.r_s_Ohm = t.last.r_s_Ohm;
  }
  return o;
}

/// Each log of the folder on its own, from the configuration's start: logs are not taken to follow one another
/// (the machine cools between sessions). A log that cannot be read is skipped with its error, in the summary and on
/// stderr, and the others go on (exit 65 at the end); a configuration error ends the run (78), as it would every log.
int run_folder(const EstimateOptions& o, const io::MachineConfig& cfg, const std::string& config_name) {
  const std::vector<std::filesystem::path> logs = logs_in_folder(o.log);
  io::create_output_directory(o.out);
  const std::string summary_path = (std::filesystem::path(o.out) / "summary.csv").string();
  FolderSummary summary(summary_path);
  std::size_t skipped = 0;
  for (std::size_t k = 0; k < logs.size(); ++k) {
    const std::string log = logs[k].string();
    std::fprintf(stderr, "rpem estimate: log %zu of %zu: %s\n", k + 1, logs.size(), log.c_str());
    const std::string out = estimate_path(o.out, logs[k]);
    LogOutcome outcome;
    try {
      outcome = outcome_of(run_log(o, log, out, cfg, config_name));
    } catch (const io::ConfigError&) {
      throw;
    } catch (const io::InputError& e) {
      ++skipped;
      std::fprintf(stderr, "rpem estimate: skipped: %s\n", e.what());
      outcome.error = e.what();
      std::error_code ec;
      std::filesystem::remove(out, ec);  // a log read part-way leaves no estimate beside the others
    }
    outcome.log = logs[k].filename().string();
    outcome.started = session_start(logs[k]);
    summary.add(outcome);
  }
  std::fprintf(stderr, "rpem estimate: %zu logs: %zu estimated, %zu skipped; summary in %s\n", logs.size(),
               logs.size() - skipped, skipped, summary_path.c_str());
  return skipped > 0 ? kExitDataError : kExitOk;
}

int run_estimate(const EstimateOptions& o) {
  io::MachineConfig cfg = machine_config_or_builtin(o.config, "rpem estimate");
  if (!o.algorithm.empty()) cfg.estimator.algorithm = io::parse_algorithm(o.algorithm);
  const std::string config_name = o.config.empty() ? "builtin:paper-ipmsm" : o.config;
  if (std::filesystem::is_directory(o.log)) return run_folder(o, cfg, config_name);
  io::require_output_directory(o.out);  // before the log is read, which may take long
  (void)run_log(o, o.log, o.out, cfg, config_name);
  return kExitOk;
}

}  // namespace

Runner add_estimate_command(CLI::App& app) {
  auto opts = std::make_shared<EstimateOptions>();
  CLI::App* cmd = app.add_subcommand("estimate", "Run the RPEM estimator offline over a drive log");
  add_log_options(*cmd, opts->log, opts->log_map, "", LogPath::kFileOrFolder);
  cmd->add_option("--config", opts->config, "machine and estimator YAML (default: built-in paper-ipmsm.yaml)")
      ->check(CLI::ExistingFile);
  writes_file(cmd->add_option("--out", opts->out,
                              "estimate CSV to write; with a folder of logs, the folder to write each log's estimate "
                              "and summary.csv in"),
              Written::kFileOrFolder)
      ->required();
  cmd->add_option("--algorithm", opts->algorithm, "override the configured gain algorithm")
      ->check(CLI::IsMember({"sga", "gna", "phyint"}));
  CLI::Option* every = cmd->add_option("--every", opts->every, "write every N-th sample's estimate (default 1: all)")
                           ->check(CLI::PositiveNumber);
  cmd->add_option("--rate", opts->rate_Hz,
                  "write estimates at this rate [Hz] of the log's time (the first sample at or after each 1/rate), "
                  "e.g. 100 for an 8 kHz log: 1/80 of the file (docs/drive-log.md, \"Estimate CSV\")")
      ->check(CLI::Range(1e-9, 1e9))  // a grid of 1 ns to 32 years: its period in ns fits the log's int64 time
      ->excludes(every);
  cmd->add_option("--thermal", opts->thermal,
                  "thermal.yaml: run the thermal network's filter beside the estimator (docs/thermal.md)")
      ->check(CLI::ExistingFile);
  return [cmd, opts]() { return cmd->parsed() ? run_estimate(*opts) : -1; };
}

}  // namespace rpem::tools
