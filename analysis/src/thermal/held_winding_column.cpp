#include "rpem/analysis/thermal/held_winding_column.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <optional>

#include "rpem/analysis/normal_quantile.hpp"
#include "rpem/analysis/thermal/thermal_replay.hpp"
#include "rpem/core/non_finite.hpp"
#include "rpem/core/thermal_held_reading.hpp"
#include "rpem/core/thermal_observer.hpp"

namespace rpem::analysis {
namespace {

using core::kInf;
using core::kNaN;

/// r̂s's winding temperature at one step and its standard deviation [°C, K].
struct WindingObservation {
  double t_C = 0.0, sigma_K = 0.0;
};

/// A run of one reading, with the r̂s observations (14.28b) compares.
struct ReadingRun {
  HeldWindingRun run;
  std::vector<WindingObservation> observations;
};

/// ρ of eq. 14.28b: the law's coefficient at copper's reference against the largest of its material.
double move_scale(const core::DriftLaw& copper) {
  const double alpha20 = copper.referred_to(core::kMaterialReference_C).coeff_per_K;
  const std::optional<core::MaterialCoefficient> m = core::material_of(core::kWindingMaterials, alpha20);
  return m ? alpha20 / m->max_per_K : 1.0;
}

/// q of eq. 14.28b: the smallest step between two consecutive readings of a session.
double column_resolution_K(const ThermalRecord& r) {
  double q = kInf;
  for (std::size_t j = 0; j < r.session_first_step.size(); ++j) {
    double previous = kNaN;
    for (std::size_t k = r.session_first_step[j]; k < r.session_end(j); ++k) {
      const double y = r.steps[k].winding_sensor_C;
      if (!std::isfinite(y)) continue;
      if (std::isfinite(previous) && !core::same_reading(y, previous)) q = std::min(q, std::abs(y - previous));
      previous = y;
    }
  }
  return std::isfinite(q) ? q : kCoarsestReadingResolution_K;
}

/// The runs of one reading in session j (no reading leaves a run open).
std::vector<HeldWindingRun> reading_runs(const ThermalRecord& r, std::size_t j) {
  const std::size_t begin = r.session_first_step[j], end = r.session_end(j);
  std::vector<HeldWindingRun> out;
  std::size_t first = end;                    // the open run's first step (end: none open)
  const auto close = [&](std::size_t next) {  // next: the step of the next value, or the session's end
    if (first == end) return;
    HeldWindingRun run{};
    run.first = first;
    run.end = next;
    run.t_first_s = r.t_s[first];
    run.t_last_s = r.t_s[next - 1];
    run.log = r.session_logs.at(j);
    run.value_C = r.steps[first].winding_sensor_C;
    run.whole_session =
        next == end && std::none_of(r.steps.begin() + static_cast<std::ptrdiff_t>(begin),
                                    r.steps.begin() + static_cast<std::ptrdiff_t>(first),
                                    [](const core::ThermalStepData& s) { return std::isfinite(s.winding_sensor_C); });
    out.push_back(std::move(run));
  };
  for (std::size_t k = begin; k < end; ++k) {
    const double y = r.steps[k].winding_sensor_C;
    if (!std::isfinite(y)) continue;
    if (first != end && core::same_reading(y, r.steps[first].winding_sensor_C)) continue;
    close(k);
    first = k;
  }
  close(end);
  return out;
}

/// The runs of one reading in session j, each with the r̂s observations not within 5·τ_s of the next change.
void collect_runs(const ThermalRecord& r, std::size_t j, const core::DriftLaw& copper, double tau_s,
                  std::vector<ReadingRun>& out) {
  const double per_ohm = 1.0 / std::abs(copper.value_ref * copper.coeff_per_K);
  for (HeldWindingRun& held : reading_runs(r, j)) {
    ReadingRun run;
    run.run = std::move(held);
    const double compared_until_s = run.run.end == r.session_end(j) ? kInf : r.t_s[run.run.end] - 5.0 * tau_s;
    for (std::size_t k = run.run.first; k < run.run.end && r.t_s[k] <= compared_until_s; ++k) {
      const core::ParameterObservation& p = r.steps[k].parameter[core::kRs];
      if (p.valid && std::isfinite(p.value) && p.variance >= 0.0)
        run.observations.push_back({copper.temperature_C(p.value), std::sqrt(p.variance) * per_ohm});
    }
    out.push_back(std::move(run));
  }
}

/// Sets the run's readings aside (NaN) and keeps it in `out`.
void set_run_aside(ThermalRecord& r, const HeldWindingRun& run, HeldWindingColumn& out) {
  for (std::size_t k = run.first; k < run.end; ++k) r.steps[k].winding_sensor_C = kNaN;
  out.runs.push_back(run);
}

/// Whether any reading is left: a record without one has no winding sensor.
bool has_winding_readings(const ThermalRecord& r) {
  return std::any_of(r.steps.begin(), r.steps.end(),
                     [](const core::ThermalStepData& s) { return std::isfinite(s.winding_sensor_C); });
}

/// Whether (14.28b) holds in the run; sets its moved_K and allowed_K at the widest margin.
bool is_held(ReadingRun& run, double rho, double q, double z, double sensor_sigma_K) {
  if (run.observations.size() < 2) return false;
  const WindingObservation& o0 = run.observations.front();
  double widest = -kInf;
  for (const WindingObservation& o : run.observations) {
    const double moved = rho * std::abs(o.t_C - o0.t_C);
    const double allowed =
        q + z * std::sqrt(o.sigma_K * o.sigma_K + o0.sigma_K * o0.sigma_K + 2.0 * sensor_sigma_K * sensor_sigma_K);
    if (moved - allowed > widest) {
      widest = moved - allowed;
      run.run.moved_K = moved;
      run.run.allowed_K = allowed;
    }
  }
  return widest > 0.0;
}

}  // namespace

HeldWindingColumn drop_held_winding_readings(ThermalRecord& r, const core::DriftLaw& copper, double sensor_sigma_K,
                                             double sensor_time_constant_s) {
  HeldWindingColumn out;
  if (!r.winding_sensor || r.steps.empty()) return out;
  assert(copper.value_ref > 0.0 && copper.coeff_per_K != 0.0 && sensor_sigma_K >= 0.0);
  out.resolution_K = column_resolution_K(r);
  std::vector<ReadingRun> runs;
  for (std::size_t j = 0; j < r.session_first_step.size(); ++j)
    collect_runs(r, j, copper, std::max(0.0, sensor_time_constant_s), runs);
  std::size_t comparisons = 0;
  for (const ReadingRun& run : runs) comparisons += run.observations.empty() ? 0 : run.observations.size() - 1;
  if (comparisons == 0) return out;
  out.z = upper_normal_quantile(kHeldColumnFalseRate / (2.0 * static_cast<double>(comparisons)));
  const double rho = move_scale(copper);
  for (ReadingRun& run : runs) {
    if (is_held(run, rho, out.resolution_K, out.z, sensor_sigma_K)) set_run_aside(r, run.run, out);
  }
  r.winding_sensor = has_winding_readings(r);
  return out;
}

HeldWindingColumn drop_winding_readings_the_network_holds(ThermalRecord& r, const core::ThermalFusionConfig& fitted) {
  HeldWindingColumn out;
  if (!r.winding_sensor || r.steps.empty()) return out;
  out.resolution_K = column_resolution_K(r);
  const std::vector<FilterStep> steps = run_filter(fitted, r);
  assert(steps.size() == r.steps.size());
  for (std::size_t j = 0; j < r.session_first_step.size(); ++j) {
    for (HeldWindingRun& run : reading_runs(r, j)) {
      run.found_by = HeldWindingRun::FoundBy::kFittedNetwork;
      for (std::size_t k = run.first; k < run.end; ++k) run.refused_steps += steps[k].estimate.winding_reading_held ? 1 : 0;
      if (run.refused_steps > 0) set_run_aside(r, run, out);
    }
  }
  r.winding_sensor = has_winding_readings(r);
  return out;
}

std::vector<std::string> HeldWindingColumn::describe(const std::string& column) const {
  std::vector<std::string> s;
  for (const HeldWindingRun& h : runs) {
    char line[768];
    char span[256];
    if (h.whole_session) {
      std::snprintf(span, sizeof span, "on every step of %s", h.log.c_str());
    } else {
      std::snprintf(span, sizeof span, "in %s from t %.1f s to %.1f s", h.log.c_str(), h.t_first_s, h.t_last_s);
    }
    if (h.found_by == HeldWindingRun::FoundBy::kFittedNetwork) {
      std::snprintf(line, sizeof line,
                    "%s holds %.4g °C %s (%zu steps) while the network fitted to it says the winding moved away: the "
                    "filter refused it as held on %zu of them (docs/derivations.md eq. 14.28c): %s; the network "
                    "is fitted again without it",
                    column.c_str(), h.value_C, span, h.end - h.first, h.refused_steps,
                    h.whole_session ? "no such sensor there, read as absent" : "a held value, not a reading: not used");
    } else {
      std::snprintf(line, sizeof line,
                    "%s holds %.4g °C %s (%zu steps) while the winding r̂s reads moved by %.3g K, more than the %.3g K "
                    "a live reading's resolution (%.3g K) and noise allow (z %.2f; docs/derivations.md eq. 14.28b): %s",
                    column.c_str(), h.value_C, span, h.end - h.first, h.moved_K, h.allowed_K, resolution_K, z,
                    h.whole_session ? "no such sensor there, read as absent" : "a held value, not a reading: not used");
    }
    s.emplace_back(line);
  }
  return s;
}

}  // namespace rpem::analysis
