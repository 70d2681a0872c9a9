#pragma once
// Regimes: what each sample is, decided before it reaches an estimator or a fit (docs/derivations.md §13).
// A real drive's data pass through states the rotor-frame model does not describe or in which a parameter
// is not observable: the bridge not modulating, the dq frame not the rotor's (open-loop start-up), a current
// too small for r_s' term to stand out, a window whose mean the steady state does not represent. One
// classifier decides this for every consumer (AveragedDriveEstimator, DriveEstimator, `rpem diagnose`).
//
// Every threshold is a statistical test at one significance z (`estimator.regimes.significance_sigma`)
// against the noise and resolution measured from the data themselves, plus the configuration's own
// uncertainty (D_M's bounds, the inductances' tolerance). With e = u − r·i − (x/ω_n)·di/dt − n·J·x·i the
// voltage the model leaves to the magnet (pu, rotor frame, nominal r and x):
//   bridge off   |u_reported|² ≤ c₂·σ_u²  and  |i|² ≤ c₂·σ_i²        c₂ = −2·ln α, α = erfc(z/√2)
//   not locked   |e_d| − tan δ_tol·sgn(n)·e_q − B_d > z·σ_L         (e outside a cone about ±q: §13)
//   transient    a term the steady state leaves out (slope change, speed-current covariance; a
//                standalone sample: the decayed remnant e^{−Δt/τ_el}·|Δi|) beyond z·σ of its row;
//                a mixed window: the bridge was released or took over inside it (the window next to a
//                bridge-off one; the release shows one window late: kPreviousMixed); or both inside it, found
//                by its neighbours: ψ = e_q/n outside both theirs, on one side, beyond z·σ of each difference
//                plus what Δr, Δx do over the operating points' difference (kPreviousMixed, one window late)
//   excites ψm   |n|·ψ_min − Δr·|i_q| − |n|·Δx_d·|i_d| > z·h_ψ·N_ψ   (h² = γ/(2 − γ): the estimator's averaging)
//   excites r_s  r_min·|i| − |n|·(Δψ + Δx·|i|) − n_reach·F   > z·h_r·N_r
//                n_reach = max(|n|, the speeds at the window's reads): a frame's error acts at the speeds the window
//                passed through, which its mean hides where the rotor turned back inside it (a sensorless stall)
//                F = 0 for a sensor's frame; sensorless: ψ_max·2·sin(δ_max/2), the largest frame error the lock test
//                passes, δ_max = δ_tol + asin(min(1, cos δ_tol·(B_d + tan δ_tol·B_q + z·σ_L)/(|n|·ψ_min)))
//                Hall sensors (below their speed): δ_max no larger than their own frame error
//                a frame assumed a sensor's (angle_source not given): decided with F = 0, and flagged where only
//                F = 0 lets the term stand out (kRsOnAssumedFrame)
// Real-time safe: noexcept, no allocation, fixed size.

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "rpem/core/types.hpp"

namespace rpem::core {

/// A sample's regime: the first of these that holds, in this order of precedence from kInvalid down.
/// Stable numbers (written in estimate CSVs, counted in RPEM_DIAGNOSTICS): never renumber.
enum class Regime : std::uint8_t {
  kExcitesBoth = 0,  ///< admitted; ψm's and r_s' terms both stand out of their noise and confounders
  kExcitesPsiM = 1,  ///< admitted; only ψm's term does
  kExcitesRs = 2,    ///< admitted; only r_s' term does
  kUnexcited = 3,    ///< admitted, but neither term stands out: adapts nothing
  kTransient = 4,    ///< excluded: the steady state (with the inductive correction) does not represent it
  kNotLocked = 5,    ///< excluded: the reported dq frame is not the rotor's
  kBridgeOff = 6,    ///< excluded: the bridge is not modulating (voltage and current zero at speed)
  kInvalid = 7,      ///< excluded: not finite
};
inline constexpr std::size_t kRegimeCount = 8;

/// Every test that held, whatever the precedence (a CSV's `regime_bits`).
namespace regime_bit {
inline constexpr std::uint8_t kBridgeOff = 1U << 0;
inline constexpr std::uint8_t kNotLocked = 1U << 1;
inline constexpr std::uint8_t kTransient = 1U << 2;
inline constexpr std::uint8_t kExcitesPsiM = 1U << 3;
inline constexpr std::uint8_t kExcitesRs = 1U << 4;
inline constexpr std::uint8_t kInvalid = 1U << 5;
/// Not this sample's: the window before it (its chain's, adjacent) is mixed, transient from now on
/// (docs/derivations.md §13, "Mixed windows"): it held the bridge's release (this one is bridge off, that one was
/// not), or a release and a take-over both (its flux left both neighbours', "… inside one window"). An online
/// consumer retracts what it adapted there; counts move it (RegimeCounts).
inline constexpr std::uint8_t kPreviousMixed = 1U << 6;
/// Not a test of its own: r_s' term stood out only because the frame's source was not given and a position
/// sensor's was assumed (RegimeSettings::angle_source_assumed); a sensorless frame's possible error would have
/// kept it below its noise. Decides nothing; the tools count it and say which key settles it.
inline constexpr std::uint8_t kRsOnAssumedFrame = 1U << 7;
inline constexpr std::uint8_t kExcluded = kBridgeOff | kNotLocked | kTransient | kInvalid;
}  // namespace regime_bit

/// The regime the bits give (the precedence of Regime).
[[nodiscard]] constexpr Regime regime_of(std::uint8_t bits) noexcept {
  using namespace regime_bit;
  if (bits & kInvalid) return Regime::kInvalid;
  if (bits & kBridgeOff) return Regime::kBridgeOff;
  if (bits & kNotLocked) return Regime::kNotLocked;
  if (bits & kTransient) return Regime::kTransient;
  const bool psi = (bits & kExcitesPsiM) != 0, rs = (bits & kExcitesRs) != 0;
  return psi ? (rs ? Regime::kExcitesBoth : Regime::kExcitesPsiM) : (rs ? Regime::kExcitesRs : Regime::kUnexcited);
}

struct Classification {
  Regime regime = Regime::kUnexcited;
  std::uint8_t bits = 0;
  [[nodiscard]] static constexpr Classification of(std::uint8_t b) noexcept { return {regime_of(b), b}; }
  /// Adapts nothing and enters no fit.
  [[nodiscard]] constexpr bool excluded() const noexcept { return (bits & regime_bit::kExcluded) != 0; }
  [[nodiscard]] constexpr bool excites_psi_m() const noexcept { return !excluded() && (bits & regime_bit::kExcitesPsiM); }
  [[nodiscard]] constexpr bool excites_r_s() const noexcept { return !excluded() && (bits & regime_bit::kExcitesRs); }
};

/// What a sample carries where classification is off (estimator.regimes.enabled: false): admitted as
/// exciting both.
inline constexpr Classification kUnclassified = Classification::of(regime_bit::kExcitesPsiM | regime_bit::kExcitesRs);

/// One row of the regime catalogue: its name (CSV, counters, reports) and whether it is excluded.
struct RegimeInfo {
  Regime regime;
  const char* name;
  bool excluded;
};
inline constexpr std::array<RegimeInfo, kRegimeCount> kRegimes{{
    {Regime::kExcitesBoth, "excites_both", false},
    {Regime::kExcitesPsiM, "excites_psi_m", false},
    {Regime::kExcitesRs, "excites_r_s", false},
    {Regime::kUnexcited, "unexcited", false},
    {Regime::kTransient, "transient", true},
    {Regime::kNotLocked, "not_locked", true},
    {Regime::kBridgeOff, "bridge_off", true},
    {Regime::kInvalid, "invalid", true},
}};
[[nodiscard]] constexpr const RegimeInfo& info(Regime r) noexcept { return kRegimes[static_cast<std::size_t>(r)]; }

/// The regime of a sample found mixed afterwards (kPreviousMixed on the next): transient, unless a test of
/// higher precedence already excluded it.
[[nodiscard]] constexpr Regime as_mixed(Regime r) noexcept { return info(r).excluded ? r : Regime::kTransient; }

/// Samples per regime; a sample found mixed by the next one's kPreviousMixed moves to its regime as_mixed().
/// Beside them, the admitted samples that excited r_s only on an assumed sensor's frame (kRsOnAssumedFrame).
/// Real-time safe.
struct RegimeCounts {
  std::array<std::uint64_t, kRegimeCount> n{};
  std::uint64_t r_s_on_assumed_frame = 0;
  Regime last = Regime::kInvalid;      ///< the regime the last sample counted in
  bool last_on_assumed_frame = false;  ///< the last sample counted in r_s_on_assumed_frame
  bool has_last = false;
  void add(Classification c) noexcept {
    if ((c.bits & regime_bit::kPreviousMixed) && has_last) {
      --n[static_cast<std::size_t>(last)];
      ++n[static_cast<std::size_t>(as_mixed(last))];
      r_s_on_assumed_frame -= last_on_assumed_frame ? 1 : 0;  // mixed: transient, it adapted nothing
    }
    ++n[static_cast<std::size_t>(c.regime)];
    last = c.regime;
    last_on_assumed_frame = c.excites_r_s() && (c.bits & regime_bit::kRsOnAssumedFrame) != 0;
    r_s_on_assumed_frame += last_on_assumed_frame ? 1 : 0;
    has_last = true;
  }
  [[nodiscard]] std::uint64_t operator[](Regime r) const noexcept { return n[static_cast<std::size_t>(r)]; }
  [[nodiscard]] std::uint64_t total() const noexcept;
  [[nodiscard]] std::uint64_t excluded() const noexcept;
};

/// `angle_source: hall`'s defaults: the nearest of six 60° states (a VESC below foc_hall_interp_erpm reads the
/// state's angle from its table: mcpwm_foc.c / foc_math.c, foc_correct_hall), and the speed above which a VESC in
/// Hall mode takes its observer's angle (foc_sl_erpm, mcconf_default.h: 2000 erpm, electrical).
inline constexpr double kHallFrameErrorRad = kPi / 6.0;
inline constexpr double kHallBelowSpeedRadS = 2000.0 * 2.0 * kPi / 60.0;
/// ... and the speed below which it holds each state's angle instead of interpolating between transitions
/// (foc_hall_interp_erpm, mcconf_default.h: 500 erpm, electrical).
inline constexpr double kHallInterpolationSpeedRadS = 500.0 * 2.0 * kPi / 60.0;

/// The classification's keys as users give them (`estimator.regimes`, docs/configuration.md), SI.
struct RegimeSettings {
  /// false: no sample is classified (every one admitted as exciting both parameters, none judged as an
  /// outlier): the estimator as the paper states it, for comparison.
  bool enabled = true;
  /// z of every test: a term counts as present beyond z standard deviations of its noise (two-sided
  /// false rate erfc(z/√2): 6.3e-5 at 4).
  double significance_sigma = 4.0;
  /// The data's resolution [V, A, rad/s] (the quantum of the reported values); 0: measured from the data
  /// (the smallest nonzero change between consecutive samples).
  double voltage_resolution_V = 0.0;
  double current_resolution_A = 0.0;
  double speed_resolution_rad_s = 0.0;
  /// How far the machine's (differential) inductances may be from the configured ones, relative:
  /// 0.3 = the Beckhoff AM8141's datasheet L against its measured flux map (data/, docs/derivations.md §13).
  double inductance_tolerance = 0.3;
  /// The largest angle between the back-EMF and ±q a locked frame shows: acos(0.98), the frame error
  /// that biases the q-axis flux by 2 %.
  double angle_tolerance_rad = 0.20033484232311968;
  /// Where the drive's dq frame comes from. false (`angle_source: sensor`): a position sensor; the frame is the
  /// rotor's but for a constant offset (`model_extensions`), wherever the lock test cannot judge it. true
  /// (`sensorless`, `hall`): an observer or an open-loop start-up; r_s is excited only beyond the frame error the lock
  /// test leaves possible (docs/derivations.md §13, "Excitation") — with Hall sensors, below hall_below_speed_rad_s,
  /// beyond the smaller of that and hall_frame_error_rad.
  bool sensorless = false;
  /// `angle_source: hall`: the largest error of the Hall sensors' frame (π/6: the nearest of six 60° states, as a
  /// VESC reads them below foc_hall_interp_erpm); 0: no Hall sensors.
  double hall_frame_error_rad = 0.0;
  /// The electrical speed below which the frame is the Hall sensors' (a VESC's foc_sl_erpm, 2000 erpm by default;
  /// the observer's above).
  double hall_below_speed_rad_s = 0.0;
  /// The electrical speed below which the Hall sensors' angle is a staircase (a VESC's foc_hall_interp_erpm, 500 erpm
  /// by default): there an averaged sample's speed is its step count's where it has one (core::window_speed_rad_s);
  /// 0: no Hall sensors.
  double hall_interpolation_speed_rad_s = 0.0;
  /// The configuration did not say where the frame comes from: decided as a sensor's (sensorless false), and a
  /// window whose r_s excitation a sensorless frame would not have is flagged (regime_bit::kRsOnAssumedFrame).
  bool angle_source_assumed = false;
};

/// The classifier's configuration, per unit (make_regime_config() in settings.hpp builds it).
struct RegimeConfig {
  double z = 4.0;        ///< significance of the one-dimensional tests
  double chi2 = 19.334;  ///< c₂ = −2·ln α: the same significance for a two-dimensional zero test
  double omega_n_rad_s = 1.0;
  double r_pu = 0.0, r_min_pu = 0.0, dr_pu = 0.0;            ///< nominal r_s, D_M's smallest, largest deviation
  double psi_min_pu = 0.0, psi_max_pu = 0.0, dpsi_pu = 0.0;  ///< D_M's ψm range, largest deviation from nominal
  double x_d_pu = 0.0, x_q_pu = 0.0;                         ///< nominal inductances
  double dx_d_pu = 0.0, dx_q_pu = 0.0;                       ///< their tolerance
  double tan_angle = 0.0;                                    ///< tan δ_tol
  bool sensorless = false;                                   ///< RegimeSettings::sensorless
  double hall_frame_error_rad = 0.0;                         ///< RegimeSettings::hall_frame_error_rad (0: none)
  double hall_below_n_pu = 0.0;                              ///< RegimeSettings::hall_below_speed_rad_s / ω_n
  bool angle_source_assumed = false;                         ///< RegimeSettings::angle_source_assumed
  /// Configured resolution of u, i, n [pu]; 0: measured.
  std::array<double, 3> resolution_pu{};
  /// τ_el = max(x)/(ω_n·r_min) [s]: the slowest decay of the electrical transient the model admits.
  double electrical_time_constant_s = 0.0;
  /// A control-rate stream is classified in blocks of this many samples (StreamClassifier): N·γ_L,max ≤ 1 %.
  int stream_block = 1;
};

/// How a sample relates to the one before it; the estimator decides.
enum class SampleTiming : std::uint8_t {
  kFirst = 0,       ///< nothing before it in the chain (first sample, after a gap): no transient test
  kDense = 1,       ///< a control-rate sample of the predictor's chain: the dynamic model holds
  kContiguous = 2,  ///< a steady-state observation adjacent to the previous one (consecutive windows)
  kStandalone = 3,  ///< a steady-state observation far from the previous one (sparse instantaneous rows)
};

/// One sample as the classifier takes it: rotor frame, per unit, the model's corrections applied.
struct RegimeInput {
  SampleTiming timing = SampleTiming::kFirst;
  std::int64_t t_ns = 0;     ///< end of the sample (of its window)
  double window_s = 0.0;     ///< length of its averaging window (0: instantaneous)
  Vec2 u_pu = Vec2::Zero();  ///< the voltage the model takes (mean over the interval or window)
  Vec2 i_pu = Vec2::Zero();  ///< measured current (window mean)
  double n_pu = 0.0;         ///< speed (window mean)
  /// The error of n_pu the caller states, and its noise (a tracker's speeds rebuilt to the window's mean:
  /// AveragedSample::omega_el_error_rad_s, omega_el_error_noise_rad_s); 0: the speed is the window's own.
  double n_error_pu = 0.0;
  double n_error_noise_pu = 0.0;
  /// The largest |speed| the window is known to have passed through beyond its mean (its reads':
  /// AveragedSample::omega_el_at_reads_max_rad_s); 0: only the mean is known. A sensorless frame's error acts at it.
  double n_reach_pu = 0.0;
  double u_reported_sq_pu = 0.0;  ///< |u|² as the drive reports it, before corrections (bridge off)
  /// The voltage and current as the drive reported them, before the model's corrections (a command turned into
  /// the applied mean, the sampled means' term): their resolution is measured here, since a correction's
  /// continuous term makes every change nonzero and hides the quantum (docs/derivations.md §13, "Noise and
  /// resolution, measured").
  /// NaN (not given): u_pu and i_pu are as reported.
  Vec2 u_reported_pu = Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
  Vec2 i_reported_pu = Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
  /// The current's slope over the sample's window where the caller knows it (a block of a control-rate
  /// stream: its end points); otherwise (NaN) the classifier takes it between consecutive samples.
  Vec2 di_dt_pu_s = Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
  /// The estimator's gain for this sample per parameter, γ_L (a batch fit over N samples: 1/N): how much
  /// of one sample's noise its estimate keeps, h² = γ/(2 − γ).
  Vec2 weight = Vec2::Ones();
};

/// How many residuals |r| of a quantity start its noise median (docs/derivations.md §13, "Noise"): their exact
/// median, robust to (K − 1)/2 = 8 transient ones among them (a run-up's two corners: ≤ 2 per lane each, u and
/// i two lanes), before the tracker steps from it. From the quantity's first nonzero residual.
inline constexpr int kNoiseWarmUp = 17;

/// The noise of a quantity [pu]: σ² = (median/0.6745)² + q²/12 (the measured noise and the quantisation).
struct RegimeNoise {
  double u_sq = 0.0, i_sq = 0.0, n_sq = 0.0;  ///< σ² of u, i, n
};

/// A window as the test against its neighbours takes it (docs/derivations.md §13, "… inside one window"): the flux
/// the nominal model leaves to the magnet, its noise, and the levers the configuration's tolerance acts through.
struct WindowFlux {
  double psi_pu = 0.0;  ///< ψ = e_q/n, e = u − r·i − (x/ω_n)·s − n·J·x·i (s: the inductive correction's slope)
  /// ψ's variance per σ_u², σ_i², σ_n², and from a stated speed error's noise.
  double var_per_u = 0.0, var_per_i = 0.0, var_per_n = 0.0, var_stated_pu = 0.0;
  /// What a stated speed error E can put there, (ψ_max + x_d·|i_d|)·|E/n|, and a sensorless frame's share.
  double bias_pu = 0.0;
  /// Where Δr and Δx_d act on ψ (i_q/n, i_d), and the inductive correction (s_q/n).
  double lever_r = 0.0, lever_x_d = 0.0, lever_x_q = 0.0;
  bool valid = false;    ///< a window of the chain admitted as exciting ψm
  bool settled = false;  ///< no noise median was warming up when it entered: its noise may judge it
  [[nodiscard]] double variance(const RegimeNoise& v) const noexcept {
    return var_per_u * v.u_sq + var_per_i * v.i_sq + var_per_n * v.n_sq + var_stated_pu;
  }
};

struct RegimeState {
  /// Per quantity (u, i, n): the running median of the normalised second difference |r| (its noise, with
  /// σ = median/0.6745), and the smallest nonzero change seen (its resolution; +∞: none yet).
  std::array<double, 3> noise_median_pu{};
  std::array<double, 3> measured_resolution_pu{};
  /// Whether a second difference of a chain has been seen: before, no test that excludes a chain's sample
  /// can be judged (a standalone sample is judged on the resolution at least).
  bool noise_known = false;
  /// The chain's last two samples: u, i, n and the time of each [s, relative to t_origin_ns].
  std::array<Vec2, 2> u_pu{}, i_pu{};
  std::array<double, 2> n_pu{}, t_s{};
  /// The chain's last sample as reported (RegimeInput::u_reported_pu): the next change the resolution is read from.
  Vec2 u_reported_pu = Vec2::Zero(), i_reported_pu = Vec2::Zero();
  std::int64_t t_origin_ns = 0;  ///< the first sample's time (times are kept relative to it)
  bool has_origin = false;
  int points = 0;                  ///< samples held (0–2)
  int chained = 0;                 ///< of those, how many a chain joins to this one (dense, contiguous)
  Vec2 slope_pu_s = Vec2::Zero();  ///< di/dt the sample's inductive correction takes (0: none)
  Vec2 previous_slope_pu_s = Vec2::Zero();
  double inv_dt = 0.0, previous_inv_dt = 0.0;  ///< 1/Δt between window centres, this sample's and the one before
  bool slope_valid = false, previous_slope_valid = false;
  bool previous_transient = false;  ///< the previous sample's own slope test failed (the junction straddles)
  /// The chain's previous sample: a window (averaged), and whether it was bridge off (mixed windows).
  bool previous_window = false, previous_bridge_off = false;
  /// The window before this one, awaiting its neighbour's judgement, and the last one before it not found mixed.
  WindowFlux flux_previous{}, flux_reference{};
  /// The noise before flux_previous entered: what it and its neighbours are judged against (neither it nor its
  /// successor has moved it).
  RegimeNoise flux_noise{};
  /// Per quantity, how many residuals its median's warm-up has still to take (0: none under way; a nonzero
  /// residual where the median is zero starts one, §13), and those taken, |r| ascending (last: read only
  /// during a warm-up).
  std::array<int, 3> noise_warm_up_left{};
  std::array<std::array<double, kNoiseWarmUp>, 3> noise_warm_up_pu{};
};

class RegimeClassifier {
 public:
  explicit RegimeClassifier(const RegimeConfig& config) noexcept;

  /// Classifies one sample and learns its noise and resolution. Real-time safe.
  [[nodiscard]] Classification step(const RegimeInput& in) noexcept;

  /// Forgets the chain (the next sample has no predecessor); the noise and resolution learnt are kept.
  void break_chain() noexcept {
    state_.points = state_.chained = 0;
    state_.slope_valid = state_.previous_slope_valid = false;
    state_.previous_window = state_.previous_bridge_off = false;
    state_.flux_previous.valid = state_.flux_reference.valid = false;
  }
  /// Everything learnt back to the start.
  void reset() noexcept;
  /// New configuration; what was learnt is kept. Not real-time.
  void reconfigure(const RegimeConfig& config) noexcept;

  [[nodiscard]] const RegimeConfig& config() const noexcept { return config_; }
  [[nodiscard]] const RegimeState& state() const noexcept { return state_; }
  /// The noise the last sample was judged against (measured before it, and the resolution).
  [[nodiscard]] const RegimeNoise& noise() const noexcept { return noise_; }
  /// The noise with everything learnt so far, the last sample included.
  [[nodiscard]] RegimeNoise current_noise() const noexcept;
  /// di/dt the last sample's inductive correction should take [pu/s] (zero where there is none).
  [[nodiscard]] const Vec2& slope_pu_s() const noexcept { return state_.slope_pu_s; }

 private:
  /// What the tests take from the configuration alone, computed once by reconfigure(): each the product a
  /// test formed per sample, in the same order of operations, so that every decision is bit-identical.
  /// The pairs are vectors here because a Vec2 built from two scalars per sample goes through memory (two
  /// 8-byte stores, one 16-byte load: a failed store forward, the largest cost the profile showed).
  struct Constants {
    double z_sq = 0.0;                                  ///< z²
    double r_sq = 0.0;                                  ///< r²
    double r_min_sq = 0.0;                              ///< r_min²
    double r_max = 0.0;                                 ///< D_M's largest r
    double psi_max_sq = 0.0;                            ///< ψ_max²
    double inv_omega_n = 0.0;                           ///< 1/ω_n
    double inv_omega_n_sq = 0.0;                        ///< 1/ω_n²
    Vec2 x = Vec2::Zero(), x_swapped = Vec2::Zero();    ///< (x_d, x_q), (x_q, x_d)
    Vec2 dx = Vec2::Zero(), dx_swapped = Vec2::Zero();  ///< (Δx_d, Δx_q), (Δx_q, Δx_d)
    Vec2 x_over_omega_n = Vec2::Zero();                 ///< (x_d, x_q)/ω_n
    Vec2 dx_over_omega_n = Vec2::Zero();                ///< (Δx_d, Δx_q)/ω_n
    Vec2 x_sq = Vec2::Zero();                           ///< (x_d², x_q²)
    Vec2 slope_var_x_sq = Vec2::Zero();                 ///< (x_d², x_q²)/ω_n²
    Vec2 flux_q = Vec2::Zero();                         ///< (0, ψ_max): the speed terms' flux, q row
    double x_max = 0.0, dx_max = 0.0;                   ///< the larger inductance and tolerance
    double cos_angle = 1.0, sin_angle = 0.0;            ///< cos δ_tol, sin δ_tol
    double cos_hall = -1.0;                             ///< cos of the Hall sensors' largest frame error (−1: none)
    double frame_least_pu = 0.0;  ///< a sensorless frame's least error as a flux (0: a sensor's): r_s' first check
    double slope_reach = 0.0;     ///< (x_q + Δx_q)/ω_n: what the inductive correction may miss, per |s_q/n|
    double frame_reach_pu = 0.0;  ///< ½·ψ_max·(1 − cos δ_tol) for a sensorless or Hall frame, else 0
  };

  /// Recomputes quantisation_var_ (after a resolution changed or the configuration did).
  void update_quantisation() noexcept;
  /// step()'s parts, each against noise_ and the terms step() has just taken (regime.cpp): the slope and
  /// its state; the bridge-off, angle-lock, contiguous windows' transient and excitation bits.
  struct Terms;
  [[nodiscard]] Terms take_slope(const RegimeInput& in, double dt_s) noexcept;
  [[nodiscard]] std::uint8_t bridge_bits(const RegimeInput& in) const noexcept;  ///< kBridgeOff or 0
  /// kNotLocked or 0 (and Terms::lock_bias).
  [[nodiscard]] std::uint8_t lock_bits(const RegimeInput& in, Terms& t) const noexcept;
  /// σ_L²: the lock test's margin's variance.
  [[nodiscard]] double lock_variance(const RegimeInput& in, const Terms& t) const noexcept;
  /// A sensorless frame's largest possible error as a flux beside Δψ in r_s' test [pu] (after lock_bits).
  [[nodiscard]] double frame_flux(const RegimeInput& in, const Terms& t) const noexcept;
  [[nodiscard]] std::uint8_t contiguous_transient_bits(const RegimeInput& in, const Terms& t) noexcept;
  [[nodiscard]] std::uint8_t speed_error_bits(const RegimeInput& in, const Terms& t) const noexcept;
  [[nodiscard]] std::uint8_t excitation_bits(const RegimeInput& in, const Terms& t) const noexcept;
  /// kPreviousMixed where the previous window's flux left both neighbours' (this one's and the reference's), or 0;
  /// `bits`: this window's so far. Moves the neighbours on.
  [[nodiscard]] std::uint8_t flux_excursion_bits(const RegimeInput& in, const Terms& t, std::uint8_t bits) noexcept;
  [[nodiscard]] WindowFlux window_flux(const RegimeInput& in, const Terms& t) const noexcept;

  RegimeConfig config_;
  Constants k_;
  RegimeState state_;
  RegimeNoise noise_;
  /// q²/12 of u, i, n with q the configured resolution, else the measured one (0 while none is): the
  /// quantisation's share of each σ², kept here since it changes only where a resolution does.
  std::array<double, 3> quantisation_var_{};
};

/// The classification of a control-rate stream (DriveEstimator's dense samples): the samples' means over
/// blocks of RegimeConfig::stream_block, each block classified as one sample with the slope of its end
/// points; every sample carries the latest block's classification (docs/derivations.md §13, "Control-rate
/// streams"). A chain's first sample is classified on its own. Real-time safe.
class StreamClassifier {
 public:
  explicit StreamClassifier(const RegimeConfig& config) noexcept : classifier_(config) { reset(); }

  /// One sample (timing kDense, or kFirst where a chain starts; a dense one's weight comes from
  /// set_gain_rates()). Real-time safe.
  [[nodiscard]] Classification step(const RegimeInput& in) noexcept {
    if (in.timing == SampleTiming::kDense) return step_dense(in.t_ns, in.u_pu, in.i_pu, in.n_pu, in.u_reported_sq_pu);
    return start(in);
  }
  /// A dense sample without building its RegimeInput (the per-sample path: a few sums; every
  /// stream_block-th sample classifies the block). Real-time safe.
  [[nodiscard]] Classification step_dense(std::int64_t t_ns, const Vec2& u_pu, const Vec2& i_pu, double n_pu,
                                          double u_reported_sq_pu) noexcept {
    u_sum_ += u_pu;
    i_sum_ += i_pu;
    n_sum_ += n_pu;
    u_reported_sum_ += u_reported_sq_pu;
    if (++count_ < classifier_.config().stream_block && has_start_) [[likely]]
      return held_;
    return close_block(t_ns, i_pu);
  }
  /// The dense samples' gain rates [1/s] (γ_L = rate·Δt per sample): a block's weight is rate·span.
  void set_gain_rates(const Vec2& rate_per_s) noexcept { gain_rate_per_s_ = rate_per_s; }

  void break_chain() noexcept {
    classifier_.break_chain();
    count_ = 0;
    has_start_ = false;
  }
  void reset() noexcept;
  void reconfigure(const RegimeConfig& config) noexcept;

  [[nodiscard]] const RegimeClassifier& classifier() const noexcept { return classifier_; }
  [[nodiscard]] const RegimeNoise& noise() const noexcept { return classifier_.noise(); }
  /// The classification the samples carry now.
  [[nodiscard]] Classification held() const noexcept { return held_; }
  /// Whether a chain has started (a block is open whose classification holds).
  [[nodiscard]] bool started() const noexcept { return has_start_; }

 private:
  /// A chain's first sample (or a standalone one), judged on its own; the next block starts after it.
  [[nodiscard]] Classification start(const RegimeInput& in) noexcept;
  /// The block ending with this sample, as one sample.
  [[nodiscard]] Classification close_block(std::int64_t t_ns, const Vec2& i_pu) noexcept;
  void clear_sums() noexcept;

  RegimeClassifier classifier_;
  Classification held_;
  int count_ = 0;
  Vec2 u_sum_ = Vec2::Zero(), i_sum_ = Vec2::Zero();
  Vec2 gain_rate_per_s_ = Vec2::Zero();
  double n_sum_ = 0.0, u_reported_sum_ = 0.0;
  Vec2 i_start_ = Vec2::Zero();  ///< the current at the block's start (the previous block's last sample)
  std::int64_t start_ns_ = 0;
  bool has_start_ = false;
};

/// The significance's two-dimensional bound: c₂ = −2·ln(erfc(z/√2)), so that |v|²/σ² ~ χ²₂ exceeds it with the
/// same probability as |x|/σ exceeds z in one dimension.
[[nodiscard]] double chi2_bound(double z) noexcept;

}  // namespace rpem::core
