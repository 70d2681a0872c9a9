#include "rpem/io/sample_counts.hpp"

#include <array>
#include <cstdio>

namespace rpem::io {
namespace {

/// A rule that can take samples out of the adaptation: what it is and which keys change it. A table, so
/// that estimate and diagnose say the same.
struct Rule {
  const char* what;
  const char* why;
  const char* keys;
};

constexpr Rule kUnexcited{
    "adapted nothing (neither parameter excited)",
    "neither term stood out: ψm's back-EMF |ω|·ψ_min and R_s' drop R_min·|i| must exceed their noise as "
    "the gains average it and what the other parameters' uncertainty (D_M, the inductance tolerance) "
    "can put in their place; zero-current coasting and standstill without current excite neither; a sensorless "
    "frame (angle_source) keeps R_s from low speeds whose back-EMF cannot rule out a frame error",
    "estimator.bounds (narrower ψm bounds let R_s adapt at speed), estimator.regimes.angle_source, "
    "estimator.regimes.significance_sigma, "
    "estimator.regimes.inductance_tolerance"};
constexpr Rule kTransient{"were transient",
                          "the window's current or speed changed more than the steady state with the inductive correction "
                          "represents (a slope change, the inductance's tolerance on the correction, speed and current "
                          "changing together inside the window)",
                          "estimator.regimes.inductance_tolerance, estimator.regimes.significance_sigma; shorter windows "
                          "(a faster logger) help"};
constexpr Rule kNotLocked{
    "were not locked",
    "the back-EMF e = u − R·i − ω·J·L·i pointed off ±q by more than the angle tolerance and the "
    "configured uncertainty allow: the dq frame was not the rotor's (an open-loop start-up, a "
    "sensor offset — model_extensions.theta_offset, which rpem diagnose finds)",
    "estimator.regimes.angle_tolerance_rad, estimator.regimes.inductance_tolerance, estimator.bounds.r_s_Ohm"};
constexpr Rule kBridgeOff{"had the bridge off",
                          "the reported voltage and the current were zero within their noise and resolution while the "
                          "machine turned fast enough that a modulating bridge would have driven its short-circuit "
                          "current: the drive was not modulating (freewheeling, coasting); nothing to change if it was off",
                          "estimator.regimes.voltage_resolution_V, estimator.regimes.current_resolution_A"};
constexpr Rule kInvalid{"were not finite", "NaN or infinite values", "none (the data)"};
constexpr Rule kOutlier{"were skipped as outliers",
                        "the prediction error's pull on ψm or R_s (along the parameter's gradient, what the update moves "
                        "it by) lay further than the bound times its noise beyond what any parameter inside D_M explains",
                        "estimator.outlier_bound_sigma (0: never skip)"};
constexpr Rule kResyncPhase{"resynchronised",
                            "each was more than estimator.max_sample_interval_s after the previous one but within "
                            "estimator.max_gap_carry_s, or followed lost samples: the predictor started over and adapted "
                            "nothing (samples further apart than both are steady-state observations that adapt)",
                            "estimator.max_sample_interval_s, estimator.max_gap_carry_s"};
constexpr Rule kResyncAveraged{
    "resynchronised",
    "each followed lost windows (a gap, or a window starting later than the previous one ended "
    "by more than half its length), or was an instantaneous sample after a silence: adapted nothing",
    "none for windows (their length never resyncs); estimator.averaged.max_interval_s for "
    "instantaneous samples"};

/// Each regime's rule, in core::kRegimes' order (the admitted regimes that adapt have none).
constexpr std::array<const Rule*, core::kRegimeCount> kRules{nullptr,     nullptr,     nullptr,     &kUnexcited,
                                                             &kTransient, &kNotLocked, &kBridgeOff, &kInvalid};
static_assert(core::info(core::Regime::kUnexcited).name[0] == 'u' && core::info(core::Regime::kInvalid).excluded);

std::string sentence(std::uint64_t n, std::uint64_t total, const Rule& r) {
  char head[128];
  std::snprintf(head, sizeof head, "%llu of %llu samples (%.1f %%) ", static_cast<unsigned long long>(n),
                static_cast<unsigned long long>(total), 100.0 * static_cast<double>(n) / static_cast<double>(total));
  return std::string(head) + r.what + ": " + r.why + ". Keys: " + r.keys + ".";
}

}  // namespace

void SampleCounts::add(const core::Estimate& e) noexcept {
  ++samples;
  regimes.add(e.regime);
  const bool first = !started_;
  started_ = true;
  switch (e.detail.code) {
    case core::StepCode::kSynchronized:
      resyncs += first ? 0 : 1;
      break;
    case core::StepCode::kPredictorDiverged:
      ++resyncs;
      break;
    case core::StepCode::kOutlier:
      ++outliers;
      break;
    case core::StepCode::kAdapted:
    case core::StepCode::kRejectedNonFinite:
    case core::StepCode::kExcluded:
      break;
  }
}

std::string regime_summary(const SampleCounts& c) {
  std::string s = "regimes:";
  for (const core::RegimeInfo& r : core::kRegimes) {
    s += ' ';
    s += r.name;
    s += ' ' + std::to_string(c.regimes[r.regime]);
    s += ',';
  }
  s += " resyncs " + std::to_string(c.resyncs) + ", outliers " + std::to_string(c.outliers);
  return s;
}

std::string assumed_frame_note(const SampleCounts& c) {
  if (c.regimes.r_s_on_assumed_frame == 0) return "";
  const std::uint64_t excited = c.regimes[core::Regime::kExcitesRs] + c.regimes[core::Regime::kExcitesBoth];
  return std::to_string(c.regimes.r_s_on_assumed_frame) + " of the " + std::to_string(excited) +
         " samples that excited R_s did so only because the drive's dq frame was taken as a position sensor's: the "
         "configuration does not say where it comes from (estimator.regimes.angle_source). On an observer or an "
         "open-loop start-up (a sensorless drive: most VESCs) the back EMF there could not rule out a frame error "
         "that outweighs R_s' drop: say angle_source: sensorless and R_s does not adapt on them; with Hall sensors say "
         "angle_source: hall (their frame is within 30° of the rotor's below the observer's speed); with an encoder or "
         "a resolver say angle_source: sensor (docs/configuration.md)";
}

std::vector<std::string> exclusion_explanations(const SampleCounts& c, double share) {
  std::vector<std::string> out;
  if (c.samples == 0) return out;
  const double limit = share * static_cast<double>(c.samples);
  const auto explain = [&](std::uint64_t n, const Rule& r) {
    if (static_cast<double>(n) > limit) out.push_back(sentence(n, c.samples, r));
  };
  explain(c.resyncs, c.averaged ? kResyncAveraged : kResyncPhase);
  for (const core::RegimeInfo& r : core::kRegimes) {
    if (const Rule* rule = kRules[static_cast<std::size_t>(r.regime)]) explain(c.regimes[r.regime], *rule);
  }
  explain(c.outliers, kOutlier);
  return out;
}

}  // namespace rpem::io
