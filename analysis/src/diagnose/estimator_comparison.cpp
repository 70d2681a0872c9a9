#include "rpem/analysis/diagnose/estimator_comparison.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/clock.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/io/csv_table.hpp"

namespace rpem::analysis {
namespace {

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

EstimateSummary summarise(const ParameterTrack& track, const ParameterTrack& truth) {
  EstimateSummary s;
  if (track.empty()) return s;
  const double t0 = track.t_s.front(), t1 = track.t_s.back();
  double psi = 0.0, r = 0.0, n = 0.0, e_psi = 0.0, e_r = 0.0, m = 0.0;
  for (std::size_t k = 0; k < track.t_s.size(); ++k) {
    const double t = track.t_s[k];
    if (t >= t0 + 0.75 * (t1 - t0)) {
      psi += track.psi_m_Wb[k];
      r += track.r_s_Ohm[k];
      n += 1.0;
    }
    if (!truth.empty() && t >= t0 + 0.5 * (t1 - t0)) {
      e_psi += std::pow(track.psi_m_Wb[k] / interpolate(truth.t_s, truth.psi_m_Wb, t) - 1.0, 2);
      e_r += std::pow(track.r_s_Ohm[k] / interpolate(truth.t_s, truth.r_s_Ohm, t) - 1.0, 2);
      m += 1.0;
    }
  }
  s.psi_m_Wb = n > 0 ? psi / n : track.psi_m_Wb.back();
  s.r_s_Ohm = n > 0 ? r / n : track.r_s_Ohm.back();
  if (m > 0) {
    s.psi_m_error_pct = 100.0 * std::sqrt(e_psi / m);
    s.r_s_error_pct = 100.0 * std::sqrt(e_r / m);
  }
  return s;
}

ParameterTrack run_rpem(const LogData& log, const io::MachineConfig& config, Monitor* monitor) {
  core::DriveEstimator estimator(config.machine, config.estimator);
  ParameterTrack track;
  const std::size_t every = std::max<std::size_t>(1, log.size() / kTrackPoints);
  for (std::size_t k = 0; k < log.size(); ++k) {
    const core::Estimate e = estimator.step(log.sample(k));
    if (k % every == 0) track.add(core::to_seconds(e.t_ns), e.psi_m_Wb, e.r_s_Ohm);
    if ((k + 1) % kMonitorSamples == 0) report_work(monitor, kMonitorSamples);
  }
  report_work(monitor, log.size() % kMonitorSamples);
  return track;
}

/// Per used steady-state row: what the data implies (→ implied) and what each model assumes.
void steady_state_tracks(const LogData& log, const EffectContext& context, const ExtendedModel& model,
                         EstimatorComparison& c) {
  const core::MachineSi& machine = context.base.machine;
  const core::PerUnitBase base = core::PerUnitBase::from_rated(machine.rated);
  const core::MachinePu pu = core::to_pu(base, model.machine);
  const core::SampleConditioner conditioner(base, pu, model.extensions);
  for (std::size_t k = 0; k < log.size(); ++k) {
    if (!log.used(k)) continue;
    const core::DriveSample sample = log.sample(k);
    const core::SteadyStateInputs in = conditioner.steady_state(sample);
    if (std::abs(in.n_pu) < 1e-3 || std::abs(in.i_pu[0]) < 1e-6) continue;
    const double r_model = r_s_at(model, log, k), psi_model = psi_m_at(model, log, k);
    const double r_implied = (in.u_pu[0] + in.n_pu * in.x_q_pu * in.i_pu[1]) / in.i_pu[0];
    const double psi_implied = (in.u_pu[1] - base.resistance_pu(r_model) * in.i_pu[1]) / in.n_pu - in.x_d_pu * in.i_pu[0];
    const double t = core::to_seconds(sample.t_ns);
    c.truth.add(t, base.flux_Wb_of(psi_implied), base.resistance_Ohm_of(r_implied));
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

ParameterTrack load_truth(const std::string& path) {
  const io::CsvTable table = io::CsvTable::read(path);
  ParameterTrack t;
  t.t_s = table.column("t");
  t.psi_m_Wb = table.column("psi_m");
  t.r_s_Ohm = table.column("r_s");
  return t;
}

EstimatorComparison compare_estimates(const LogData& log, const io::MachineConfig& nominal,
                                      const io::MachineConfig& extended_config, const ExtendedModel& extended,
                                      const EffectContext& context, const ParameterTrack& truth, const WorkPool& pool,
                                      Monitor* monitor) {
  EstimatorComparison c;
  c.truth = truth;
  if (log.mode == ModelMode::kTransient) {
    c.method = "rpem";
    pool.parallel_for(2, [&](std::size_t i) {
      (i == 0 ? c.nominal : c.extended) = run_rpem(log, i == 0 ? nominal : extended_config, monitor);
    });
  } else {
    c.method = "steady_state";
    steady_state_tracks(log, context, extended, c);
  }
  c.nominal_summary = summarise(c.nominal, c.truth);
  c.extended_summary = summarise(c.extended, c.truth);
  return c;
}

}  // namespace rpem::analysis
