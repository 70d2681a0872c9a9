#pragma once
// The regime classifier as it was formulated before its cost was cut (issue 23 item 7): the reference the
// differential test (test_regime_differential.cpp) holds core::RegimeClassifier to, bit for bit. Kept
// here, in the tests, so that production code has one formulation; do not "optimise" this one: its worth
// is that it states the rules of docs/derivations.md §13 as they were derived and reviewed. The noise
// medians' start (§13, "Start (warm-up)") replaced the first-residual start in both, written here apart.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "rpem/core/clock.hpp"
#include "rpem/core/regime.hpp"

namespace rpem::test::reference {

using core::all_finite;
using core::RegimeConfig;
using core::RegimeInput;
using core::RegimeNoise;
using core::SampleTiming;
using core::to_seconds;
using core::Vec2;
namespace regime_bit = core::regime_bit;

struct State {
  /// Per quantity (u, i, n): the running median of the normalised second difference |r| (its noise, with
  /// σ = median/0.6745), and the smallest nonzero change seen (its resolution; +∞: none yet).
  std::array<double, 3> noise_median_pu{};
  std::array<double, 3> measured_resolution_pu{};
  /// Per quantity: the residuals of its warm-up in the order they came, and how many (docs/derivations.md §13).
  std::array<std::array<double, core::kNoiseWarmUp>, 3> warm_up{};
  std::array<int, 3> warm_up_count{};
  /// Whether a second difference of a chain has been seen: before, no test that excludes a chain's sample
  /// can be judged (a standalone sample is judged on the resolution at least).
  bool noise_known = false;
  /// The chain's last two samples: u, i, n and the time of each [s, relative to t_origin_ns].
  std::array<Vec2, 2> u_pu{}, i_pu{};
  std::array<double, 2> n_pu{}, t_s{};
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
  /// A window's flux against its neighbours: the window awaiting judgement, the last one before it not found mixed,
  /// and the noise before the first of them entered.
  struct Flux {
    double psi = 0.0, var_per_u = 0.0, var_per_i = 0.0, var_per_n = 0.0, var_stated = 0.0, bias = 0.0;
    double lever_r = 0.0, lever_x_d = 0.0, lever_x_q = 0.0;
    bool valid = false, settled = false;
  };
  Flux flux_previous{}, flux_reference{};
  RegimeNoise flux_noise{};
};

constexpr double kInf = std::numeric_limits<double>::infinity();
/// σ of a zero-mean normal over the median of its absolute value, 1/Φ⁻¹(3/4).
constexpr double kSigmaPerMedian = 1.4826022185056018;
/// The median tracker's step in log scale, η = 1/16: it moves by e^{±η} a sample, so the median of a
/// normal |r| settles within ≈ 13 % (σ of log m ≈ √(0.29·η), §13) and follows a change of 10× in 37 samples.
constexpr double kTrackUp = 1.0644944589178593;     // e^{1/16}
constexpr double kTrackDown = 0.93941306281347581;  // e^{−1/16}

/// The noise median of one quantity after the residual a (§13, "Noise"): a warm-up of kNoiseWarmUp residuals
/// runs from a nonzero one met by a zero median (none yet, or mostly zeros); during it, the median of those
/// taken so far — the lower middle of an even count — found by selection on a copy of them in the order they
/// came (production inserts into a sorted buffer); otherwise the tracker's step m·e^{±η}, up where |r| > m.
template <typename State>
inline double track_noise(State& s, std::size_t q, double a) noexcept {
  int& n = s.warm_up_count[q];
  const double m = s.noise_median_pu[q];
  const bool warming = n > 0 && n < core::kNoiseWarmUp;
  if (!warming && m == 0.0 && a > 0.0) n = 0;  // a warm-up starts
  if (!warming && !(m == 0.0 && a > 0.0)) return a > m ? m * kTrackUp : m * kTrackDown;
  s.warm_up[q][static_cast<std::size_t>(n)] = a;
  ++n;
  std::array<double, core::kNoiseWarmUp> taken = s.warm_up[q];
  const auto middle = taken.begin() + (n - 1) / 2;
  std::nth_element(taken.begin(), middle, taken.begin() + n);
  return *middle;
}

/// The smallest nonzero |change|; whether it became smaller.
inline bool track_resolution(double& q, double change) noexcept {
  const double a = std::abs(change), before = q;
  q = std::min(q, a > 0.0 ? a : q);
  return q < before;
}

/// Learns a sample's noise and resolution from the chain and takes it in as the chain's last. Returns
/// whether a measured resolution changed.
template <typename State>
inline bool learn(State& s, const RegimeInput& in, double t_s) noexcept {
  bool resolution_changed = false;
  if (s.points >= 1) {
    const Vec2 du = (in.u_pu - s.u_pu[0]).cwiseAbs(), di = (in.i_pu - s.i_pu[0]).cwiseAbs();
    resolution_changed =
        track_resolution(s.measured_resolution_pu[0], du[0]) | track_resolution(s.measured_resolution_pu[0], du[1]) |
        track_resolution(s.measured_resolution_pu[1], di[0]) | track_resolution(s.measured_resolution_pu[1], di[1]) |
        track_resolution(s.measured_resolution_pu[2], in.n_pu - s.n_pu[0]);
  }
  // Only a chain's samples are close enough for their second difference to be noise: a standalone
  // sample's neighbours are other operating points.
  const bool chain = in.timing == SampleTiming::kDense || in.timing == SampleTiming::kContiguous;
  const double span = t_s - s.t_s[1];
  if (s.points == 2 && chain && s.chained >= 1 && span > 0.0) {
    // The middle sample against the line through its neighbours, r = x₁ − (w·x₂ + (1 − w)·x₀) with
    // w = (t₁ − t₀)/(t₂ − t₀): zero for a ramp at any spacing; for white noise of σ its variance is
    // σ²·(1 + w² + (1 − w)²) = σ²·(3/2 + 2·d), d = (w − ½)² ∈ [0, ¼], whose root the factor removes:
    // (3/2 + 2d)^{−½} ≈ 0.81650 − 0.53215·d + 0.37763·d², within 2e-4 (no square root per sample).
    const double w = (s.t_s[0] - s.t_s[1]) / span;
    const double d = (w - 0.5) * (w - 0.5);
    const double norm = 0.81649658 + d * (-0.53215 + d * 0.37763);
    const Vec2 ru = norm * (s.u_pu[0] - (w * in.u_pu + (1.0 - w) * s.u_pu[1])).cwiseAbs();
    const Vec2 ri = norm * (s.i_pu[0] - (w * in.i_pu + (1.0 - w) * s.i_pu[1])).cwiseAbs();
    const double rn = norm * std::abs(s.n_pu[0] - (w * in.n_pu + (1.0 - w) * s.n_pu[1]));
    s.noise_median_pu[0] = track_noise(s, 0, ru[0]);
    s.noise_median_pu[0] = track_noise(s, 0, ru[1]);
    s.noise_median_pu[1] = track_noise(s, 1, ri[0]);
    s.noise_median_pu[1] = track_noise(s, 1, ri[1]);
    s.noise_median_pu[2] = track_noise(s, 2, rn);
    s.noise_known = true;
  }
  s.u_pu[1] = s.u_pu[0];
  s.i_pu[1] = s.i_pu[0];
  s.n_pu[1] = s.n_pu[0];
  s.t_s[1] = s.t_s[0];
  s.u_pu[0] = in.u_pu;
  s.i_pu[0] = in.i_pu;
  s.n_pu[0] = in.n_pu;
  s.t_s[0] = t_s;
  if (s.points < 2) ++s.points;
  s.chained = chain ? std::min(s.chained + 1, 2) : 0;
  return resolution_changed;
}

/// core::RegimeClassifier's step, break_chain, current_noise and slope, in their original formulation.
class Classifier {
 public:
  explicit Classifier(const RegimeConfig& config) noexcept {
    reconfigure(config);
    state_ = State{};
    state_.measured_resolution_pu.fill(kInf);
    noise_ = RegimeNoise{};
    update_quantisation();
  }
  void break_chain() noexcept {
    state_.points = state_.chained = 0;
    state_.slope_valid = state_.previous_slope_valid = false;
    state_.previous_window = state_.previous_bridge_off = false;
    state_.flux_previous.valid = state_.flux_reference.valid = false;
  }
  [[nodiscard]] const RegimeNoise& noise() const noexcept { return noise_; }
  [[nodiscard]] const Vec2& slope_pu_s() const noexcept { return state_.slope_pu_s; }
  [[nodiscard]] const State& state() const noexcept { return state_; }
  [[nodiscard]] RegimeNoise current_noise() const noexcept {
    const auto variance = [this](std::size_t q) {
      const double sigma = state_.noise_median_pu[q] * kSigmaPerMedian;
      return sigma * sigma + quantisation_var_[q];
    };
    return {variance(0), variance(1), variance(2)};
  }

  void reconfigure(const RegimeConfig& config) noexcept {
    config_ = config;
    const RegimeConfig& c = config;
    Constants& k = k_;
    k.z_sq = c.z * c.z;
    k.r_sq = c.r_pu * c.r_pu;
    k.r_min_sq = c.r_min_pu * c.r_min_pu;
    k.r_max = c.r_pu + c.dr_pu;
    k.psi_max_sq = c.psi_max_pu * c.psi_max_pu;
    k.inv_omega_n = 1.0 / c.omega_n_rad_s;
    k.inv_omega_n_sq = k.inv_omega_n * k.inv_omega_n;
    k.x = Vec2(c.x_d_pu, c.x_q_pu);
    k.x_swapped = k.x.reverse();
    k.dx = Vec2(c.dx_d_pu, c.dx_q_pu);
    k.dx_swapped = k.dx.reverse();
    k.x_over_omega_n = Vec2(k.inv_omega_n * c.x_d_pu, k.inv_omega_n * c.x_q_pu);
    k.dx_over_omega_n = Vec2(k.inv_omega_n * c.dx_d_pu, k.inv_omega_n * c.dx_q_pu);
    k.x_sq = Vec2(c.x_d_pu * c.x_d_pu, c.x_q_pu * c.x_q_pu);
    k.slope_var_x_sq = Vec2(k.inv_omega_n_sq * c.x_d_pu * c.x_d_pu, k.inv_omega_n_sq * c.x_q_pu * c.x_q_pu);
    k.x_max = std::max(c.x_d_pu, c.x_q_pu);
    k.dx_max = std::max(c.dx_d_pu, c.dx_q_pu);
    update_quantisation();
    state_.flux_previous.valid = state_.flux_reference.valid = false;
  }

  void update_quantisation() noexcept {
    for (std::size_t q = 0; q < 3; ++q) {
      const double measured = state_.measured_resolution_pu[q] < kInf ? state_.measured_resolution_pu[q] : 0.0;
      const double res = config_.resolution_pu[q] > 0.0 ? config_.resolution_pu[q] : measured;
      quantisation_var_[q] = res * res * (1.0 / 12.0);  // a uniform quantisation error has variance q²/12
    }
  }

  core::Classification step(const RegimeInput& in) noexcept {
    const RegimeConfig& c = config_;
    const Constants& k = k_;
    State& s = state_;
    if (!all_finite(in.u_pu, in.i_pu, in.n_pu, in.u_reported_sq_pu, in.window_s, in.weight)) [[unlikely]] {
      break_chain();
      return core::Classification::of(regime_bit::kInvalid);
    }
    if (in.timing == SampleTiming::kFirst) break_chain();
    if (!s.has_origin) [[unlikely]] {
      s.t_origin_ns = in.t_ns;
      s.has_origin = true;
    }
    // Times are window centres (a mean stands for its centre), relative to the first sample.
    const double t_s = to_seconds(in.t_ns - s.t_origin_ns) - 0.5 * in.window_s;
    const double dt_s = s.points >= 1 ? t_s - s.t_s[0] : 0.0;

    // The current's slope: given (a block's end points), or between consecutive samples of a chain.
    s.previous_slope_pu_s = s.slope_pu_s;
    s.previous_slope_valid = s.slope_valid;
    s.previous_inv_dt = s.inv_dt;
    const bool linked =
        s.points >= 1 && dt_s > 0.0 && (in.timing == SampleTiming::kDense || in.timing == SampleTiming::kContiguous);
    s.inv_dt = linked ? 1.0 / dt_s : 0.0;
    s.slope_valid = linked;
    if (!linked) {
      s.slope_pu_s.setZero();
      s.previous_transient = false;
    } else if (std::isnan(in.di_dt_pu_s[0])) {
      s.slope_pu_s = (in.i_pu - s.i_pu[0]) * s.inv_dt;
    } else {
      s.slope_pu_s = in.di_dt_pu_s;
    }

    noise_ = current_noise();
    const RegimeNoise& v = noise_;
    const Vec2& i = in.i_pu;
    const double n = in.n_pu, n2 = n * n, abs_n = std::abs(n);
    const Vec2 abs_i = i.cwiseAbs();
    // n²·x_q², n²·x_d² as every test forms them (n²·x·x).
    const double n2_xq2 = n2 * c.x_q_pu * c.x_q_pu, n2_xd2 = n2 * c.x_d_pu * c.x_d_pu;
    std::uint8_t bits = 0;

    // Bridge off: the reported voltage and the current are zero within their noise where a modulating bridge
    // could not hold a zero current: with |u| inside the voltage's zero band √c₂·σ_u the machine would carry
    // |i| = |M⁻¹·(u − e)| ≥ (|n|·ψ_min − √c₂·σ_u)/‖M‖, ‖M‖ ≤ ‖M‖_F = √(2·r² + n²·(x_d² + x_q²)) at D_M's largest r,
    // beyond the current's zero band √c₂·σ_i.
    const double i_sq = i.squaredNorm();
    if (in.u_reported_sq_pu <= c.chi2 * v.u_sq && i_sq <= c.chi2 * v.i_sq) [[unlikely]] {
      const double r = k.r_max;
      const double emf_margin = abs_n * c.psi_min_pu - std::sqrt(c.chi2 * v.u_sq);
      const double m_sq = 2.0 * r * r + n2 * (c.x_d_pu * c.x_d_pu + c.x_q_pu * c.x_q_pu);
      if (emf_margin > 0.0 && emf_margin * emf_margin > c.chi2 * v.i_sq * m_sq) bits |= regime_bit::kBridgeOff;
    }

    // Angle locked: e, what the model leaves to the magnet, lies in the cone of half-angle δ_tol about
    // sgn(n)·q, widened by what the configuration's uncertainty (r within D_M, x within its tolerance) and
    // the noise can put there. Independent of ψm's magnitude. Both axes at once: (d, q) in one vector.
    const Vec2& sl = s.slope_pu_s;
    const Vec2 abs_sl = sl.cwiseAbs();
    const Vec2 rotation = (n * k.x_swapped).cwiseProduct(i.reverse()).cwiseProduct(Vec2(1.0, -1.0));  // −n·J·x·i
    const Vec2 e = ((in.u_pu - c.r_pu * i) - k.x_over_omega_n.cwiseProduct(sl)) + rotation;
    const Vec2 b =
        (c.dr_pu * abs_i + (abs_n * k.dx_swapped).cwiseProduct(abs_i.reverse())) + k.dx_over_omega_n.cwiseProduct(abs_sl);
    // The speed's sign where it stands out of its noise; else either direction of q.
    const double along = n2 > k.z_sq * v.n_sq ? (n > 0.0 ? e[1] : -e[1]) : std::abs(e[1]);
    const double lock = std::abs(e[0]) - c.tan_angle * (along + b[1]) - b[0];
    const double slope_sq = 2.0 * s.inv_dt * s.inv_dt;  // Var(s) per σ_i²
    const double var_d =
        v.u_sq + (k.r_sq + n2_xq2 + k.slope_var_x_sq[0] * slope_sq) * v.i_sq + c.x_q_pu * c.x_q_pu * i[1] * i[1] * v.n_sq;
    const double flux_q = c.psi_max_pu + c.x_d_pu * abs_i[0];
    const double var_q = v.u_sq + (k.r_sq + n2_xd2 + k.slope_var_x_sq[1] * slope_sq) * v.i_sq + flux_q * flux_q * v.n_sq;
    const double sigma_lock = std::sqrt(var_d + c.tan_angle * c.tan_angle * var_q);
    if (lock > 0.0 && lock > c.z * sigma_lock) bits |= regime_bit::kNotLocked;
    // A sensorless frame (an observer, an open-loop start-up) that passes: a frame error δ gives e = n·ψ·[sin δ, cos δ],
    // which hides while sin(δ − δ_tol) ≤ cos δ_tol·(B_d + tan δ_tol·B_q + z·σ_L)/(|n|·ψ_min); a frame turning with
    // the rotor stays within δ_tol + π/2. Its error beside the model's [0, n·ψ̂] is |n|·ψ·2·sin(δ/2).
    double frame_flux = 0.0;
    const double reach_n = std::max(abs_n, in.n_reach_pu);  // the speeds the window passed through (its reads)
    if (c.sensorless) {
      const double delta_tol = std::atan(c.tan_angle);
      const double reach = std::cos(delta_tol) * (b[0] + c.tan_angle * b[1] + c.z * sigma_lock);
      const double delta_max = delta_tol + std::asin(std::min(1.0, reach / (abs_n * c.psi_min_pu)));
      frame_flux = 2.0 * c.psi_max_pu * std::sin(0.5 * delta_max);
    }

    if (in.timing == SampleTiming::kStandalone && s.points >= 1) [[unlikely]] {
      // A sample far from the previous one: the change of operating point between them excited a transient
      // that has decayed to e^{−Δt/τ_el} of |Δi| (τ_el the slowest the model admits). Steady if that
      // remnant is within the current's noise (its own estimate's noise, 2·decay²·σ_i², included).
      const double decay = std::exp(-dt_s / c.electrical_time_constant_s);
      const Vec2 remnant = decay * (i - s.i_pu[0]).cwiseAbs();
      const double bound = k.z_sq * v.i_sq * (1.0 + 2.0 * decay * decay);
      if (remnant.squaredNorm() > 0.0 && remnant.cwiseProduct(remnant).maxCoeff() > bound) bits |= regime_bit::kTransient;
    } else if (in.timing == SampleTiming::kContiguous && s.slope_valid) {
      // Consecutive windows: what the steady state and the inductive correction (the slope between window
      // centres) leave out, per row (d, q) in voltage:
      //   (x/ω_n)·|s_k − s_{k−1}|   the slope changed: the correction is exact only for a ramp
      //   (Δx/ω_n)·|s_k|            the inductance's tolerance on the correction
      //   x_o·|Δn|·|Δi_o|/4          mean(n·x·i) − n̄·x·ī, bounded by the ranges' product over 4
      // against the row's noise and the slope change's own noise.
      const double dn = std::abs(n - s.n_pu[0]);
      const Vec2 di = (i - s.i_pu[0]).cwiseAbs();
      Vec2 t = k.inv_omega_n * k.dx.cwiseProduct(abs_sl) + (0.25 * dn) * k.x_swapped.cwiseProduct(di.reverse());
      double slope_noise_sq = 0.0;  // Var(s_k − s_{k−1}) per σ_i²
      if (s.previous_slope_valid) {
        t += k.inv_omega_n * k.x.cwiseProduct((sl - s.previous_slope_pu_s).cwiseAbs());
        const double a = s.inv_dt, p = s.previous_inv_dt;
        slope_noise_sq = a * a + (a + p) * (a + p) + p * p;
      }
      const double slope_var = k.inv_omega_n_sq * slope_noise_sq * v.i_sq;
      const double row_d = v.u_sq + (k.r_sq + n2_xq2) * v.i_sq + k.x_sq[0] * slope_var;
      const double row_q = v.u_sq + (k.r_sq + n2_xd2) * v.i_sq + k.x_sq[1] * slope_var;
      const bool own = t[0] * t[0] > k.z_sq * row_d || t[1] * t[1] > k.z_sq * row_q;
      // A slope change shows only once both windows around the junction are in: the window after one is
      // corrected with a slope that straddles it.
      if (own || s.previous_transient) bits |= regime_bit::kTransient;
      s.previous_transient = own;
    }
    // A speed off by up to E (a tracker's reads rebuilt to the window's mean, §13 "… where the acceleration
    // changes"): the speed terms' error E·(x_q·|i_q|, x_d·|i_d| + ψ_max) per row against the row's noise with the
    // speed's own noise and E's through the same coefficients.
    if (in.n_error_pu > 0.0) {
      const double coeff_d = c.x_q_pu * abs_i[1], coeff_q = c.x_d_pu * abs_i[0] + c.psi_max_pu;
      const double cd2 = coeff_d * coeff_d, cq2 = coeff_q * coeff_q, e2 = in.n_error_pu * in.n_error_pu;
      const double row_d = v.u_sq + (k.r_sq + n2_xq2) * v.i_sq, row_q = v.u_sq + (k.r_sq + n2_xd2) * v.i_sq;
      const double speed_var = v.n_sq + in.n_error_noise_pu * in.n_error_noise_pu;
      if (e2 * cd2 > k.z_sq * (row_d + speed_var * cd2) || e2 * cq2 > k.z_sq * (row_q + speed_var * cq2)) {
        bits |= regime_bit::kTransient;
      }
    }

    // Excitation: the parameter's term, at its smallest inside D_M, less what the other terms' uncertainty
    // can put in its place, against its noise as the estimator's averaging leaves it: h² = γ/(2 − γ) of
    // one sample's variance (an exponential filter of gain γ).
    const double psi_term = abs_n * c.psi_min_pu - c.dr_pu * abs_i[1] - abs_n * c.dx_d_pu * abs_i[0];
    if (psi_term > 0.0) {
      const double h_sq = in.weight[0] / (2.0 - in.weight[0]);
      const double noise = v.u_sq + (k.r_sq + n2_xd2) * v.i_sq + k.psi_max_sq * v.n_sq;
      if (psi_term * psi_term > k.z_sq * h_sq * noise) bits |= regime_bit::kExcitesPsiM;
    }
    // r_min·|i| must at least exceed |n|·Δψ: checked on the squares before |i| is taken.
    if (k.r_min_sq * i_sq > n2 * c.dpsi_pu * c.dpsi_pu) {
      const double i_abs = std::sqrt(i_sq);
      // The frame's error at the speeds the window passed through.
      const double term = c.r_min_pu * i_abs - abs_n * (c.dpsi_pu + k.dx_max * i_abs) - reach_n * frame_flux;
      if (term > 0.0) {
        const double h_sq = in.weight[1] / (2.0 - in.weight[1]);
        const double flux = c.psi_max_pu + k.x_max * i_abs;
        const double noise = v.u_sq + (k.r_sq + n2 * k.x_max * k.x_max) * v.i_sq + flux * flux * v.n_sq;
        if (term * term > k.z_sq * h_sq * noise) bits |= regime_bit::kExcitesRs;
      }
    }

    // Before a chain has shown the data's noise, nothing in it is excluded on a threshold made of it.
    if (!s.noise_known && in.timing != SampleTiming::kStandalone) bits &= static_cast<std::uint8_t>(~regime_bit::kExcluded);

    // Mixed windows (§13): a bridge state change falls inside the window between the last one of the old
    // state and the first of the new (a read instant holds it with probability zero), whose means then mix
    // both states. The take-over: this window follows a bridge-off one; the release: this one is bridge off
    // and the one before was not — that one is mixed, which only this one shows.
    const bool window = in.window_s > 0.0;
    const bool off = (bits & regime_bit::kBridgeOff) != 0;
    if (window && in.timing == SampleTiming::kContiguous && s.previous_window) {
      if (s.previous_bridge_off && !off) bits |= regime_bit::kTransient;
      if (!s.previous_bridge_off && off) bits |= regime_bit::kPreviousMixed;
    }
    s.previous_window = window;
    s.previous_bridge_off = off;
    bits |= flux_bits(in, bits);
    if (learn(s, in, t_s)) [[unlikely]]
      update_quantisation();
    return core::Classification::of(bits);
  }

 private:
  /// A freewheel inside one window (§13): the previous window's ψ = e_q/n outside both its neighbours' (this window's,
  /// and the last before it not found mixed) on one side, each difference beyond the tolerance's reach over the
  /// levers plus z·σ; judged on the noise before it entered, and only where no median was warming up then.
  std::uint8_t flux_bits(const RegimeInput& in, std::uint8_t bits) noexcept {
    const RegimeConfig& c = config_;
    const Constants& k = k_;
    State& s = state_;
    const bool chained = in.timing == SampleTiming::kContiguous || in.timing == SampleTiming::kFirst;
    const bool candidate = in.window_s > 0.0 && chained && s.noise_known && (bits & regime_bit::kExcluded) == 0 &&
                           (bits & regime_bit::kExcitesPsiM) != 0;
    if (!candidate) {
      s.flux_previous.valid = s.flux_reference.valid = false;
      return 0;
    }
    const double n = in.n_pu, inv_n = 1.0 / n, inv_n_sq = inv_n * inv_n;
    const double i_d = in.i_pu[0], i_q = in.i_pu[1], s_q = s.slope_pu_s[1];
    State::Flux f;
    f.psi = (in.u_pu[1] - c.r_pu * i_q - k.x_over_omega_n[1] * s_q - n * c.x_d_pu * i_d) * inv_n;
    const double flux_q = c.psi_max_pu + c.x_d_pu * std::abs(i_d);
    const double flux_q_sq = flux_q * flux_q;
    const double n2_xd2 = n * n * c.x_d_pu * c.x_d_pu;
    f.var_per_u = inv_n_sq;
    const double a = k.x_over_omega_n[1] * s.inv_dt;
    f.var_per_i = (k.r_sq + 3.0 * a * (c.r_pu + a) + n2_xd2) * inv_n_sq;
    f.var_per_n = flux_q_sq * inv_n_sq;
    f.var_stated = flux_q_sq * (in.n_error_noise_pu * in.n_error_noise_pu) * inv_n_sq;
    const double cos_tol = 1.0 / std::sqrt(1.0 + c.tan_angle * c.tan_angle);
    f.bias = flux_q * std::abs(in.n_error_pu * inv_n) + (c.sensorless ? 0.5 * c.psi_max_pu * (1.0 - cos_tol) : 0.0);
    f.lever_r = i_q * inv_n;
    f.lever_x_d = i_d;
    f.lever_x_q = s_q * inv_n;
    f.valid = true;
    f.settled = true;
    for (int q : s.warm_up_count) f.settled = f.settled && !(q > 0 && q < core::kNoiseWarmUp);
    const RegimeNoise& v = s.flux_noise;
    const auto variance = [&v](const State::Flux& x) {
      return x.var_per_u * v.u_sq + x.var_per_i * v.i_sq + x.var_per_n * v.n_sq + x.var_stated;
    };
    const State::Flux& m = s.flux_previous;
    const auto side = [&](const State::Flux& o) {
      const double d = m.psi - o.psi;
      const double reach = c.dr_pu * std::abs(m.lever_r - o.lever_r) + c.dx_d_pu * std::abs(m.lever_x_d - o.lever_x_d) +
                           k.inv_omega_n * (c.x_q_pu + c.dx_q_pu) * (std::abs(m.lever_x_q) + std::abs(o.lever_x_q)) +
                           (m.bias + o.bias);
      const double excess = std::abs(d) - reach;
      if (!(excess > 0.0 && excess * excess > k.z_sq * (variance(m) + variance(o)))) return 0;
      return d > 0.0 ? 1 : -1;
    };
    bool mixed = false;
    if (m.valid && m.settled && s.flux_reference.valid) {
      const int left = side(s.flux_reference);
      mixed = left != 0 && left == side(f);
    }
    if (!mixed) s.flux_reference = s.flux_previous;
    s.flux_previous = f;
    s.flux_noise = noise_;
    return mixed ? regime_bit::kPreviousMixed : 0;
  }

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
    double x_max = 0.0, dx_max = 0.0;                   ///< the larger inductance and tolerance
  };

  RegimeConfig config_;
  Constants k_;
  State state_;
  RegimeNoise noise_;
  std::array<double, 3> quantisation_var_{};
};

}  // namespace rpem::test::reference
