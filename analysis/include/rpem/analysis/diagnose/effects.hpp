#pragma once
// The catalogue of effects `rpem diagnose` can name (docs/diagnose.md, "The catalogue"), as a table: one
// row per effect — its name, its scaled parameters with their bounds, the logs that can show it, how it
// enters the model (apply), what it reports in SI (describe), what it cannot be told apart from and which
// data would separate them, and when a fitted value is physically implausible. Adding an effect is adding
// a row to analysis/src/diagnose/catalogue.cpp; nothing else in the diagnosis switches over effects.
//
// For the fit each effect's parameters are scaled so that 0 is the model without it (the baseline's
// value) and 1 a typical magnitude. Every effect adds to the model it is applied to, so effects found in
// a log add to those the configuration already has.

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/core/conditioner.hpp"
#include "rpem/core/settings.hpp"
#include "rpem/core/thermal.hpp"

namespace rpem::analysis {

/// The model diagnose replays: the machine's constants, its model extensions, and how R_s and ψm move
/// through the log — against the logged temperatures (laws whose value at their reference temperature
/// is the machine's constant; value_ref is not used) or, without temperatures, a relative trend over the
/// log centred on its middle.
struct ExtendedModel {
  core::MachineSi machine;
  core::ModelExtensions extensions;
  std::optional<core::DriftLaw> r_s_law, psi_m_law;
  double r_s_trend = 0.0, psi_m_trend = 0.0;
};

/// A temperature column of the log.
struct TemperatureColumn {
  bool logged = false;
  double mean_C = 0.0;
  double span_K = 0.0;  ///< between its 5th and 95th percentile
};

/// Facts of the log and the machine that the parametrisations and descriptions need.
struct EffectContext {
  ModelMode mode = ModelMode::kTransient;
  core::MachineSi machine;                  ///< as configured
  ExtendedModel base;                       ///< the configuration's whole model (extensions and drift laws), the baseline
  double base_current_A = 0.0;              ///< I_b
  double max_i_d_A = 0.0, max_i_q_A = 0.0;  ///< largest |i_d|, |i_q| logged
  double extreme_i_d_A = 0.0;               ///< the logged i_d of largest magnitude, signed
  double min_i_d_A = 0.0, max_signed_i_d_A = 0.0;  ///< the logged i_d's range (1st to 99th percentile)
  double max_speed_rad_s = 0.0;
  double speed_spread_rel = 0.0;  ///< LogData::speed_spread_rel
  double t_start_s = 0.0, t_span_s = 0.0;
  std::size_t sessions = 1;  ///< LogData::sessions: a drift against time has no meaning across several
  TemperatureColumn t_winding, t_magnet;
  double reference_C = core::kMaterialReference_C;  ///< temperature at which reported drift laws are referred
  double sample_period_s = 0.0;                     ///< median sample interval
  double mean_u_dc_V = 0.0;
  double switching_frequency_Hz = 0.0;  ///< 0: unknown (t_dead_s is then not reported)
  /// Every session that takes part logs d/q values; false where one's were rebuilt from the duty cycle's magnitude
  /// (LogData::uses_rebuilt_voltages; docs/drive-log.md, "Logs without d/q values").
  bool voltages_logged = true;
  /// The frame is a sensorless observer's or Hall sensors' (estimator.regimes.sensorless): it has open-loop start-ups.
  bool frame_sensorless = false;

  /// `base`: the configuration's model as it replays on this log (make_base_model).
  [[nodiscard]] static EffectContext of(const LogData& log, const core::MachineSi& machine, const ExtendedModel& base,
                                        double reference_C, double switching_frequency_Hz);
};

/// The configuration's whole model for a log (docs/diagnose.md, item "The configuration is the baseline"):
/// its model extensions and its drift laws, which act against the log's temperature columns (referred to
/// the column's mean temperature, where the fit is best conditioned); a law whose column the log lacks
/// cannot act and leaves the constant.
[[nodiscard]] ExtendedModel make_base_model(const core::MachineSi& machine, const core::ModelExtensions& extensions,
                                            const std::optional<core::DriftLaw>& r_s_law,
                                            const std::optional<core::DriftLaw>& psi_m_law, const LogData& log);

/// The temperature columns of a log: their span and mean over the used rows, each row's temperature the one
/// the models take (SampleStore::t_winding_held_C).
[[nodiscard]] TemperatureColumn winding_column(const LogData& log);
[[nodiscard]] TemperatureColumn magnet_column(const LogData& log);

/// A drift coefficient against a temperature column is a candidate only when the column spans at least
/// this much (docs/diagnose.md, "Drift laws"): copper's 0.39 %/K moves R_s by 3.9 % over it, NdFeB's
/// −0.1 %/K ψm by 1 %, both well above what the held-out test resolves.
inline constexpr double kMinDriftSpan_K = 10.0;

/// Effects that are told by their growth with speed (iron loss) are candidates only in a log whose speed in
/// motion varies by at least this share of its largest (LogData::speed_spread_rel).
inline constexpr double kMinSpeedSpread = 0.2;

/// A saturation that changes an inductance by less than this over the logged currents is negligible: within
/// the tolerance of any data sheet and of no consequence to the estimator.
inline constexpr double kNegligibleInductanceChange = 0.01;

/// One named SI parameter of a found effect (`text` for non-numeric ones such as the phase).
struct NamedValue {
  std::string name;
  double value = 0.0;
  std::string text;
};

/// Another effect this one can be mistaken for, and the data that would separate them.
struct Confusion {
  std::string_view other;
  std::string_view separating_data;
};

/// Why a fitted effect is not physical, and what the residual it explains more likely is.
struct Implausibility {
  std::string reason;
  std::string more_likely;
};

struct Effect;

/// One row of the catalogue.
struct EffectRow {
  std::string_view name;
  int parameters = 1;                    ///< scaled parameters
  bool per_phase = false;                ///< a candidate once per phase
  bool steady_state = true;              ///< a steady-state log can show it
  std::string_view not_in_steady_state;  ///< why it cannot (diagnosis.json not_identifiable)
  std::string_view shows_as;             ///< the residual's signature (report, docs)
  std::string_view enters;               ///< how it enters the model (docs)
  std::vector<Confusion> confusions;
  /// The calibrated constant (index into kCalibrated) the effect's law is referred to — a drift law holds
  /// the constant's value at the log's mean temperature (or mid-log) — and that is therefore fitted with the
  /// effect even where the baseline could not calibrate it alone (a log at one operating point); −1: none.
  int frees_constant = -1;
  /// The calibrated constant (index into kCalibrated) that the effect's curve multiplies — the level of
  /// L_d(i) = L_d·f(i) — and that is therefore fitted with it. The curve's columns are that constant's
  /// column weighted by a factor bounded on the logged currents, so a log that cannot identify the constant
  /// cannot identify the curve either: the effect is named only if, fitted with it, the constant is
  /// admissible and identified (docs/diagnose.md, "An effect that shapes a constant"); −1: none.
  int shapes_constant = -1;
  /// The constant fitted with the effect whatever the baseline calibrates (frees_constant or
  /// shapes_constant); −1: none.
  [[nodiscard]] int fitted_constant() const { return frees_constant >= 0 ? frees_constant : shapes_constant; }
  /// Starting points (scaled) for effects whose residual is not convex in their parameters; the
  /// screening tries each and the fit starts from the best. Empty: zero.
  std::vector<std::vector<double>> starts;
  /// Whether this log can show it at all (beyond its kind); nullptr: always.
  bool (*applies)(const EffectContext&) = nullptr;
  /// Bounds of scaled parameter i; nullptr: unbounded.
  std::pair<double, double> (*bounds)(const EffectContext&, int i) = nullptr;
  /// Adds the effect with scaled parameters p to the model.
  void (*apply)(const Effect&, const double* p, const EffectContext&, ExtendedModel&) = nullptr;
  /// Its SI parameters as they stand in a model (the configuration's part included).
  std::vector<NamedValue> (*describe)(const Effect&, const ExtendedModel&, const EffectContext&) = nullptr;
  /// Whether the fitted effect is too small to matter physically (an inductance that moves by less than
  /// kNegligibleInductanceChange over the logged currents); nullptr: never. Such an effect is not named,
  /// however much residual it takes: it stands in for some other error of the model.
  bool (*negligible)(const Effect&, const ExtendedModel&, const EffectContext&) = nullptr;
  /// Set when the fitted model is physically implausible beyond its parameters' 95 % half-widths
  /// (scaled; empty: exact); nullptr: always plausible.
  std::optional<Implausibility> (*judge)(const Effect&, const ExtendedModel&, const EffectContext&,
                                         const std::vector<double>& half_width) = nullptr;
};

/// The catalogue, in the order candidates are listed.
[[nodiscard]] const std::vector<EffectRow>& catalogue();
/// The row of an effect by name (throws std::invalid_argument naming the catalogue for an unknown one).
[[nodiscard]] const EffectRow& effect_row(std::string_view name);

struct Effect {
  const EffectRow* row = nullptr;
  int phase = -1;  ///< 0, 1, 2 (a, b, c) for the per-phase effects
  [[nodiscard]] std::string name() const { return std::string(row->name); }
  [[nodiscard]] std::string label() const;  ///< with the phase, e.g. "current_offset(b)"
  bool operator==(const Effect&) const = default;
};

/// The effect by name (and phase).
[[nodiscard]] Effect effect(std::string_view name, int phase = -1);

/// Every candidate this log could show.
[[nodiscard]] std::vector<Effect> candidates(const EffectContext& c);

/// Effects this kind of log cannot show at all, with the reason (diagnosis.json "not_identifiable").
struct Unidentifiable {
  std::vector<std::string> effects;
  std::string reason;
};
[[nodiscard]] std::vector<Unidentifiable> unobservable(const EffectContext& c);

/// What data would tell two effects apart (the catalogue's confusions; a general answer otherwise).
[[nodiscard]] std::string separating_data(const Effect& a, const Effect& b);

/// Bounds of the scaled parameter i (±∞ where the physics sets none).
[[nodiscard]] std::pair<double, double> parameter_bounds(const Effect& e, const EffectContext& c, int i);

/// The machine's constants that the baseline calibrates (docs/diagnose.md, "The calibrated baseline"):
/// ψm, R_s, L_d, L_q, each as a relative change, scaled so that 1 is 1 %.
inline constexpr std::array<const char*, 4> kCalibrated{"psi_m_Wb", "r_s_Ohm", "l_d_H", "l_q_H"};
inline constexpr double kCalibrationScale = 0.01;
/// A calibrated constant stays within ±50 % of the configuration's.
inline constexpr double kCalibrationBound = 50.0;

/// Why this log cannot identify each calibrated constant whatever its excitation (kCalibrated order; empty: it
/// can): rebuilt voltages (docs/drive-log.md, "Logs without d/q values") hold the configuration in u_d, and with
/// a sensorless frame no lock test excludes the open-loop start-ups where R_s is excited.
[[nodiscard]] std::array<std::string_view, 4> withheld_constants(const EffectContext& c);

/// The machine's fields in kCalibrated order.
inline constexpr std::array<double core::MachineSi::*, 4> kCalibratedFields{
    &core::MachineSi::psi_m_Wb, &core::MachineSi::r_s_Ohm, &core::MachineSi::l_d_H, &core::MachineSi::l_q_H};

/// R_s and ψm of a model at sample k of the log [Ω, Wb].
[[nodiscard]] double r_s_at(const ExtendedModel& m, const LogData& log, std::size_t k) noexcept;
[[nodiscard]] double psi_m_at(const ExtendedModel& m, const LogData& log, std::size_t k) noexcept;

/// A drift law of a model as the configuration records it: referred to `reference_C`, value_ref the
/// model's constant.
[[nodiscard]] core::DriftLaw recorded_law(const core::DriftLaw& law, double value_at_law_reference, double reference_C);

}  // namespace rpem::analysis
