#pragma once
// The catalogue of effects `rpem diagnose` can name (docs/diagnose.md). Each is a model extension with
// named SI parameters (docs/model-extensions.md). For the fit, each effect's parameters are scaled so
// that 0 is the nominal model and 1 a typical magnitude; describe() gives them back in SI.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/core/conditioner.hpp"
#include "rpem/core/settings.hpp"

namespace rpem::analysis {

enum class EffectKind : int {
  kDeadtime = 0,   ///< inverter voltage error −sign(i)·v_err per leg
  kLdSaturation,   ///< L_d(i_d) = L_d,nom·(level + curvature·i_d²)
  kLqSaturation,   ///< L_q(i_q)
  kThetaOffset,    ///< encoder misalignment
  kCurrentOffset,  ///< per-phase current sensor offset
  kCurrentGain,    ///< per-phase current sensor gain error
  kRsDrift,        ///< R_s against winding temperature or time
  kPsimDrift,      ///< ψm against magnet temperature or time
  kDelay,          ///< the command acts late
  kIronLoss,       ///< resistance parallel to the induced voltage
};

struct Effect {
  EffectKind kind = EffectKind::kDeadtime;
  int phase = -1;  ///< 0, 1, 2 (a, b, c) for the per-phase sensor effects
  [[nodiscard]] std::string name() const;   ///< catalogue name, e.g. "current_offset"
  [[nodiscard]] std::string label() const;  ///< with the phase, e.g. "current_offset(b)"
  bool operator==(const Effect&) const = default;
};

/// A parameter's drift: value = nominal·(1 + offset + slope·x), x the time through the log (0 … 1) or
/// the temperature above the reference [K].
struct DriftLaw {
  enum class Basis { kNone, kTime, kTemperature };
  Basis basis = Basis::kNone;
  double offset = 0.0;
  double slope = 0.0;
};

/// The drift's factor at time fraction `tau` (0 … 1 through the log) or temperature `temperature_C`.
[[nodiscard]] double drift_factor(const DriftLaw& d, double tau, const std::optional<double>& temperature_C,
                                  double reference_C) noexcept;

/// The model diagnose replays: the nominal machine with model extensions and drifts.
struct ExtendedModel {
  core::ModelExtensions extensions;
  DriftLaw r_s, psi_m;
};

/// Facts of the log and the machine that the parametrisations and descriptions need.
struct EffectContext {
  ModelMode mode = ModelMode::kTransient;
  core::MachineSi machine;
  core::ModelExtensions base_extensions;  ///< the input configuration's own: part of the nominal model
  double base_current_A = 0.0;       ///< I_b
  double max_i_d_A = 0.0, max_i_q_A = 0.0;  ///< largest |i_d|, |i_q| logged
  double max_speed_rad_s = 0.0;
  double t_start_s = 0.0, t_span_s = 0.0;
  bool t_winding = false, t_magnet = false;  ///< temperature columns present
  double reference_C = 20.0;         ///< temperature at which the nominal r_s and ψm hold
  double sample_period_s = 0.0;      ///< median sample interval
  double mean_u_dc_V = 0.0;
  double switching_frequency_Hz = 0.0;  ///< 0: unknown (t_dead_s is then not reported)

  [[nodiscard]] static EffectContext of(const LogData& log, const core::MachineSi& machine,
                                        const core::ModelExtensions& base_extensions, double reference_C,
                                        double switching_frequency_Hz);
};

/// Every candidate this log could show (one per phase for the per-phase sensor effects).
[[nodiscard]] std::vector<Effect> candidates(const EffectContext& c);

/// Effects this kind of log cannot show at all, with the reason (diagnosis.json "not_identifiable").
struct Unidentifiable {
  std::vector<std::string> effects;
  std::string reason;
};
[[nodiscard]] std::vector<Unidentifiable> unobservable(const EffectContext& c);

[[nodiscard]] int parameter_count(const Effect& e, const EffectContext& c) noexcept;
/// Bounds of the scaled parameter i (±large where the physics sets none).
[[nodiscard]] std::pair<double, double> parameter_bounds(const Effect& e, const EffectContext& c, int i);

/// Adds the effect with scaled parameters p to the model.
void apply(const Effect& e, const double* p, const EffectContext& c, ExtendedModel& model);

/// One named SI parameter of a found effect (`text` for non-numeric ones such as the phase).
struct NamedValue {
  std::string name;
  double value = 0.0;
  std::string text;
};
[[nodiscard]] std::vector<NamedValue> describe(const Effect& e, const double* p, const EffectContext& c);

}  // namespace rpem::analysis
