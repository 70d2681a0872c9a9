#include "rpem/analysis/diagnose/verdict.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "../median.hpp"

namespace rpem::analysis {
namespace {

/// The median of χ²₁: a squared standard normal lies below it half the time.
constexpr double kMedianChiSquare1 = 0.454936;
/// Var(r_{k+1} − 2·r_k + r_{k−1}) / Var(r) for white r.
constexpr double kSecondDifferenceGain = 6.0;

/// v with three significant digits.
std::string three_significant(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

/// What a residual at harmonic h of the electrical angle (dq frame) is most often.
std::string harmonic_meaning(int h) {
  if (h == 0)
    return "an error that depends on the operating point (saturation of another shape, cross-saturation, a "
           "resistance or flux error varying with the load)";
  if (h == 1) return "a current-sensor offset or an unbalanced winding";
  if (h == 2) return "a current-sensor gain error or an unbalanced impedance";
  if (h % 6 == 0)
    return "rotor-frame flux harmonics of another form, or an inverter voltage error of another shape than "
           "the catalogue's dead time";
  return "an angle-periodic error outside the catalogue (encoder eccentricity, slotting)";
}

/// What a residual correlated with a regressor most likely is.
std::string regressor_meaning(const std::string& r) {
  if (r.rfind("T_", 0) == 0) return "a temperature dependence the catalogue's drift laws do not carry";
  if (r.rfind("time", 0) == 0) return "a drift over the log (heating without logged temperatures)";
  if (r.find("speed") != std::string::npos) return "a speed-dependent error (angle, delay, iron loss, the EMF's shape)";
  return "a current-dependent error (resistance, the inverter's voltage error, saturation)";
}

}  // namespace

const char* to_string(VerdictKind k) noexcept {
  switch (k) {
    case VerdictKind::kExplained:
      return "explained";
    case VerdictKind::kUnexplained:
      return "unexplained";
    case VerdictKind::kUndetermined:
      return "undetermined";
  }
  return "undetermined";
}

void SecondDifferences::add(const LogData& log, std::size_t k, const ModelSample& m) {
  valid_ += m.valid ? 1 : 0;
  // A difference needs three consecutive predicted samples of one block with no gap before the last two.
  if (previous_.valid && last_.valid && m.valid && previous_.k + 1 == last_.k && last_.k + 1 == k &&
      !log.samples.gap_before(last_.k) && !log.samples.gap_before(k)) {
    const core::Vec2 e = m.residual_A - 2.0 * last_.r + previous_.r;
    d2_.push_back(e[0] * e[0]);
    q2_.push_back(e[1] * e[1]);
  }
  previous_ = last_;
  last_ = {k, m.residual_A, m.valid};
}

void SecondDifferences::append(const SecondDifferences& other) {
  d2_.insert(d2_.end(), other.d2_.begin(), other.d2_.end());
  q2_.insert(q2_.end(), other.q2_.begin(), other.q2_.end());
  valid_ += other.valid_;
}

NoiseFloor SecondDifferences::noise_floor(const LogData& log) && {
  NoiseFloor f;
  f.differences = d2_.size();
  if (d2_.size() < kMinNoiseDifferences) {
    f.unknown_reason = "only " + std::to_string(d2_.size()) + " of the " + std::to_string(log.size()) +
                       " samples have replayed neighbours on both sides within their block (" +
                       std::to_string(kMinNoiseDifferences) + " are needed): ";
    if (log.mode == ModelMode::kSteadyState) {
      f.unknown_reason += std::to_string(log.excluded_transitional) +
                          " rows are in transition between operating points and " + std::to_string(log.excluded_idle) +
                          " idle, so no stretch of rows repeats an operating point " +
                          "(standstill under current included) and " + std::to_string(valid_) + " rows are replayed";
    } else {
      f.unknown_reason +=
          "gaps and left-out samples leave " + std::to_string(valid_) + " replayed samples without runs of three";
    }
    return f;
  }
  const double scale = 1.0 / (kSecondDifferenceGain * kMedianChiSquare1);
  const double value = std::sqrt(scale * (median(std::move(d2_)) + median(std::move(q2_))));
  if (!(value > 0.0)) {
    f.unknown_reason = "the residual does not change between neighbouring samples (below the log's resolution)";
    return f;
  }
  f.value_A = value;
  return f;
}

NoiseFloor measure_noise_floor(const LogData& log, const ReplayOutput& replay) {
  SecondDifferences all;
  for (int b = 0; b < log.blocks; ++b) {
    all.start();
    for (std::size_t k = log.block_first[static_cast<std::size_t>(b)]; k < log.block_first[static_cast<std::size_t>(b) + 1];
         ++k) {
      all.add(log, k,
              ModelSample{replay.residual_A[k], replay.model_A.empty() ? core::Vec2::Zero() : replay.model_A[k],
                          replay.valid[k]});
    }
  }
  return std::move(all).noise_floor(log);
}

Verdict verdict(double final_heldout_rms_A, const NoiseFloor& floor, const ResidualStatistics& st) {
  Verdict v;
  v.noise_floor_A = floor.value_A;
  if (floor.value_A) {
    v.ratio = final_heldout_rms_A / *floor.value_A;
    v.kind = *v.ratio <= kExplainedRatio ? VerdictKind::kExplained : VerdictKind::kUnexplained;
    if (v.explained()) return v;
  } else {
    v.kind = VerdictKind::kUndetermined;
    v.findings.push_back("the noise floor cannot be measured on this log: " + floor.unknown_reason);
    v.findings.push_back("the final model's held-out residual is " + three_significant(final_heldout_rms_A) +
                         " A RMS; whether that is the sensors' noise or a model error cannot be told without it");
  }
  const std::string floor_text =
      floor.value_A ? "noise floor " + three_significant(*floor.value_A) + " A" : "noise floor unknown";

  // Where it lives: standstill against motion, and the region that carries the most.
  if (st.standstill_samples == 0) {
    v.findings.push_back("no samples at standstill; in motion " + three_significant(st.motion_rms_A.after) + " A RMS (" +
                         floor_text + ")");
  } else if (st.motion_samples == 0) {
    v.findings.push_back("at standstill " + three_significant(st.standstill_rms_A.after) + " A RMS, no samples in motion (" +
                         floor_text + ")");
  } else {
    v.findings.push_back("at standstill " + three_significant(st.standstill_rms_A.after) + " A RMS, in motion " +
                         three_significant(st.motion_rms_A.after) + " A RMS (" + floor_text + ")");
  }
  const RegionStatistics* worst = nullptr;
  for (const RegionStatistics& r : st.regions) {
    if (!worst || r.rms_A.after > worst->rms_A.after) worst = &r;
  }
  if (worst) {
    v.findings.push_back("largest in the region " + worst->speed + ", " + worst->load + ": " +
                         three_significant(worst->rms_A.after) + " A RMS, mean ε_d " +
                         three_significant(worst->mean_d_A.after) + " A, ε_q " + three_significant(worst->mean_q_A.after) +
                         " A");
  }
  // Against the electrical angle: the strongest harmonic, if it stands out of the noise.
  const HarmonicContent* strongest = nullptr;
  for (const HarmonicContent& h : st.harmonics) {
    if (!strongest || h.amplitude_A.after > strongest->amplitude_A.after) strongest = &h;
  }
  if (strongest && floor.value_A && strongest->amplitude_A.after > *floor.value_A) {
    v.findings.push_back("against the electrical angle the residual is strongest at harmonic " +
                         std::to_string(strongest->order) + " (" + three_significant(strongest->amplitude_A.after) +
                         " A): most often " + harmonic_meaning(strongest->order));
  }
  // With what it moves.
  const RegressorCorrelation* best = nullptr;
  double best_r = 0.0;
  for (const RegressorCorrelation& c : st.correlations) {
    const double r = std::max(std::abs(c.d.after), std::abs(c.q.after));
    if (r > best_r) {
      best_r = r;
      best = &c;
    }
  }
  if (best && best_r >= 0.3) {
    v.findings.push_back("it correlates with " + best->regressor + " (" + three_significant(best_r) +
                         "): " + regressor_meaning(best->regressor));
  }
  if (!floor.value_A) {
    v.findings.emplace_back(
        "three or more consecutive samples at one operating point (a steady stretch, or standstill under "
        "current) in several blocks would measure the noise floor");
  }
  v.findings.emplace_back(
      "a log with more operating points — standstill at several currents of both signs, several speeds at "
      "several loads, temperatures that span tens of kelvin — would tell more effects apart");
  return v;
}

}  // namespace rpem::analysis
