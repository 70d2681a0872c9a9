#include "rpem/analysis/diagnose/estimator_comparison.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <optional>
#include <string>

#include "../median.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/non_finite.hpp"
#include "rpem/io/csv_table.hpp"
#include "rpem/io/errors.hpp"

namespace rpem::analysis {
namespace {

using core::kNaN;

/// Points kept per track.
constexpr std::size_t kTrackPoints = 2000;

/// Linear interpolation of a track's column at t (clamped at the ends).
double interpolate(const std::vector<double>& t, const std::vector<double>& v, double at) {
  if (t.empty()) return 0.0;
  const auto it = std::lower_bound(t.begin(), t.end(), at);
  if (it == t.begin()) return v.front();
  if (it == t.end()) return v.back();
  const std::size_t j = static_cast<std::size_t>(it - t.begin());
  const double w = (at - t[j - 1]) / std::max(t[j] - t[j - 1], 1e-300);
  return v[j - 1] + w * (v[j] - v[j - 1]);
}

/// A relative error over the terms added where the truth was finite (determined there): the RMS against a true
/// track; against what rows imply, the median of its magnitude, since a few rows the steady-state model cannot
/// represent (a transient inside a window, an unlocked start-up too slow to judge) imply anything at all.
struct RelativeError {
  bool robust = false;
  std::vector<double> magnitudes;
  void add(double value, double truth) {
    if (std::isfinite(truth)) magnitudes.push_back(std::abs(value / truth - 1.0));
  }
  [[nodiscard]] std::optional<double> pct() const {
    if (magnitudes.empty()) return std::nullopt;
    if (robust) return 100.0 * median(magnitudes);
    double sum = 0.0;
    for (double e : magnitudes) sum += e * e;
    return 100.0 * std::sqrt(sum / static_cast<double>(magnitudes.size()));
  }
};

/// `implied`: `truth` is what the steady-state rows imply (one value per row of the track, NaN where not
/// determined), else a true track (e.g. a simulation's).
EstimateSummary summarise(const ParameterTrack& track, const ParameterTrack& truth, bool implied) {
  EstimateSummary s;
  if (track.empty()) return s;
  // What the rows imply is compared row by row (a row where it is not determined is NaN, and interpolating would
  // carry the NaN to its neighbours).
  assert(!implied || truth.empty() || truth.t_s == track.t_s);
  const double t0 = track.t_s.front(), t1 = track.t_s.back();
  double psi = 0.0, r = 0.0, n = 0.0;
  RelativeError e_psi{implied, {}}, e_r{implied, {}};
  for (std::size_t k = 0; k < track.t_s.size(); ++k) {
    const double t = track.t_s[k];
    if (t >= t0 + 0.75 * (t1 - t0)) {
      psi += track.psi_m_Wb[k];
      r += track.r_s_Ohm[k];
      n += 1.0;
    }
    if (!truth.empty() && t >= t0 + kJudgedFromFraction * (t1 - t0)) {
      e_psi.add(track.psi_m_Wb[k], implied ? truth.psi_m_Wb[k] : interpolate(truth.t_s, truth.psi_m_Wb, t));
      e_r.add(track.r_s_Ohm[k], implied ? truth.r_s_Ohm[k] : interpolate(truth.t_s, truth.r_s_Ohm, t));
    }
  }
  s.psi_m_Wb = n > 0 ? psi / n : track.psi_m_Wb.back();
  s.r_s_Ohm = n > 0 ? r / n : track.r_s_Ohm.back();
  s.psi_m_error_pct = e_psi.pct();
  s.r_s_error_pct = e_r.pct();
  return s;
}

ParameterTrack run_rpem(const LogData& log, const io::MachineConfig& config, Monitor* monitor) {
  core::DriveEstimator estimator(config.machine, config.estimator);
  ParameterTrack track;
  const std::size_t every = std::max<std::size_t>(1, log.size() / kTrackPoints);
  for (std::size_t k = 0; k < log.size(); ++k) {
    if (log.starts_session(k)) estimator.reset();  // each session from the configuration, as its log alone
    const core::Estimate e = estimator.step(log.sample(k));
    if (k % every == 0) track.add(core::to_seconds(e.t_ns), e.psi_m_Wb, e.r_s_Ohm);
    if ((k + 1) % kMonitorSamples == 0) report_work(monitor, kMonitorSamples);
  }
  report_work(monitor, log.size() % kMonitorSamples);
  return track;
}

/// Per used steady-state row: what the data implies (→ truth; NaN where the row does not determine it) and what
/// each model assumes.
void steady_state_tracks(const LogData& log, const EffectContext& context, const ExtendedModel& model,
                         const core::RegimeNoise& noise, double z, EstimatorComparison& c) {
  const core::MachineSi& machine = context.base.machine;
  const core::PerUnitBase base = core::PerUnitBase::from_rated(machine.rated);
  const core::MachinePu pu = core::to_pu(base, model.machine);
  const core::SampleConditioner conditioner(base, pu, model.extensions);
  const double z_sq = z * z;
  for (std::size_t k = 0; k < log.size(); ++k) {
    if (!log.used(k)) continue;
    const core::DriveSample sample = log.sample(k);
    const core::SteadyStateInputs in = conditioner.steady_state(sample);
    const double r_model = r_s_at(model, log, k), psi_model = psi_m_at(model, log, k);
    const double n = in.n_pu, i_d = in.i_pu[0], i_q = in.i_pu[1], r = base.resistance_pu(r_model);
    // ψm = (u_q − r·i_q)/n − x_d·i_d, and its variance from the noise of u, i and n to first order.
    const double psi_emf = in.u_pu[1] - r * i_q;
    const double psi_implied = psi_emf / n - in.x_d_pu * i_d;
    const double psi_var = (noise.u_sq + (r * r + n * n * in.x_d_pu * in.x_d_pu) * noise.i_sq) / (n * n) +
                           (psi_emf * psi_emf) / (n * n * n * n) * noise.n_sq;
    // r_s = (u_d + n·x_q·i_q)/i_d, likewise.
    const double r_implied = (in.u_pu[0] + n * in.x_q_pu * i_q) / i_d;
    const double r_var = (noise.u_sq + (n * n * in.x_q_pu * in.x_q_pu + r_implied * r_implied) * noise.i_sq +
                          in.x_q_pu * in.x_q_pu * i_q * i_q * noise.n_sq) /
                         (i_d * i_d);
    // Determined where the value stands out of its noise by z (both false where n or i_d is 0: ∞ or NaN).
    const bool psi_determined = psi_implied * psi_implied > z_sq * psi_var;
    const bool r_determined = r_implied * r_implied > z_sq * r_var;
    const double t = core::to_seconds(sample.t_ns);
    c.implied.add(t, psi_determined ? base.flux_Wb_of(psi_implied) : kNaN,
                  r_determined ? base.resistance_Ohm_of(r_implied) : kNaN);
    c.nominal.add(t, psi_m_at(context.base, log, k), r_s_at(context.base, log, k));
    c.extended.add(t, psi_model, r_model);
  }
}

}  // namespace

double estimator_heldout_rms_A(const LogData& log, const io::MachineConfig& config, Monitor* monitor) {
  core::DriveEstimator estimator(config.machine, config.estimator);
  double sum = 0.0;
  std::size_t n = 0;
  for (int b = 0; b < log.blocks; ++b) {
    for (std::size_t k = log.block_first[static_cast<std::size_t>(b)]; k < log.block_first[static_cast<std::size_t>(b) + 1];
         ++k) {
      if (log.starts_session(k)) estimator.reset();
      const core::Estimate e = estimator.step(log.sample(k));
      if ((k + 1) % kMonitorSamples == 0) report_work(monitor, kMonitorSamples);
      if (b % 2 != 1 || !log.used(k) || e.detail.code != core::StepCode::kAdapted) continue;
      sum += e.epsilon_A.squaredNorm();
      ++n;
    }
  }
  report_work(monitor, log.size() % kMonitorSamples);
  return n ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
}

ParameterTrack load_truth(const std::string& path, double judged_from_s, double judged_to_s) {
  ParameterTrack t;
  try {  // the truth is data: its faults are the data's (exit 65), as a log's
    // Only the three columns are the truth's: a simulator's truth may carry more, text among them (rpem sim
    // --vesc-tool-truth's `regime`).
    const io::CsvTable table = io::CsvTable::read_numeric(path, {"t", "psi_m", "r_s"});
    t.t_s = table.column("t");
    t.psi_m_Wb = table.column("psi_m");
    t.r_s_Ohm = table.column("r_s");
  } catch (const io::DriveLogError&) {
    throw;
  } catch (const io::InputError& e) {
    throw io::DriveLogError(e.file(), e.line(), 0, e.field(), e.reason());
  }
  if (t.empty()) throw io::DriveLogError(path, 0, 0, "", "the truth has no rows");
  for (std::size_t k = 0; k < t.t_s.size(); ++k) {
    const std::size_t line = k + 2;  // after the header
    if (k > 0 && !(t.t_s[k] > t.t_s[k - 1]))
      throw io::DriveLogError(
          path, line, 0, "t",
          "the time does not increase (" + std::to_string(t.t_s[k]) + " s after " + std::to_string(t.t_s[k - 1]) + " s)");
    if (!(t.psi_m_Wb[k] > 0.0) || !std::isfinite(t.psi_m_Wb[k]))
      throw io::DriveLogError(path, line, 0, "psi_m", "not a positive finite flux linkage");
    if (!(t.r_s_Ohm[k] > 0.0) || !std::isfinite(t.r_s_Ohm[k]))
      throw io::DriveLogError(path, line, 0, "r_s", "not a positive finite resistance");
  }
  // Covered up to the truth's own step at either end (a truth sampled more coarsely than the log).
  double step = 0.0;
  for (std::size_t k = 1; k < t.t_s.size(); ++k) step = std::max(step, t.t_s[k] - t.t_s[k - 1]);
  if (t.t_s.size() > 1 && (t.t_s.front() > judged_from_s + step || t.t_s.back() < judged_to_s - step)) {
    throw io::DriveLogError(path, 0, 0, "t",
                            "the truth covers " + std::to_string(t.t_s.front()) + " to " + std::to_string(t.t_s.back()) +
                                " s; the estimates are judged over the log's second half, " + std::to_string(judged_from_s) +
                                " to " + std::to_string(judged_to_s) + " s");
  }
  return t;
}

EstimatorComparison compare_estimates(const LogData& log, const io::MachineConfig& nominal,
                                      const io::MachineConfig& extended_config, const ExtendedModel& extended,
                                      const EffectContext& context, const ParameterTrack& truth,
                                      const core::RegimeNoise& noise_pu, const WorkPool& pool, Monitor* monitor) {
  EstimatorComparison c;
  c.truth = truth;
  if (log.mode == ModelMode::kTransient) {
    c.method = "rpem";
    pool.parallel_for(2, [&](std::size_t i) {
      (i == 0 ? c.nominal : c.extended) = run_rpem(log, i == 0 ? nominal : extended_config, monitor);
    });
  } else {
    c.method = "steady_state";
    steady_state_tracks(log, context, extended, noise_pu, nominal.estimator.regimes.significance_sigma, c);
  }
  // A given truth is the reference on either kind of log; without one, a steady-state log's rows are.
  const bool implied = c.truth.empty();
  const ParameterTrack& reference = implied ? c.implied : c.truth;
  c.nominal_summary = summarise(c.nominal, reference, implied);
  c.extended_summary = summarise(c.extended, reference, implied);
  return c;
}

}  // namespace rpem::analysis
