#include "rpem/core/regime.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "rpem/core/assert.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/core/non_finite.hpp"

namespace rpem::core {
namespace {

/// σ of a zero-mean normal over the median of its absolute value, 1/Φ⁻¹(3/4).
constexpr double kSigmaPerMedian = 1.4826022185056018;
/// The median tracker's step in log scale, η = 1/16: it moves by e^{±η} a sample, so the median of a
/// normal |r| settles within ≈ 13 % (σ of log m ≈ √(0.29·η), §13) and follows a change of 10× in 37 samples.
constexpr double kTrackUp = 1.0644944589178593;     // e^{1/16}
constexpr double kTrackDown = 0.93941306281347581;  // e^{−1/16}

/// regime_of() for every combination of the bits, by look-up: the precedence as a chain of conditional
/// jumps on bits that vary from sample to sample costs a misprediction now and then.
/// Every value of the bits' byte has its entry.
constexpr std::size_t kBitCombinations = std::size_t{std::numeric_limits<std::uint8_t>::max()} + 1;
constexpr std::array<Regime, kBitCombinations> kRegimeOfBits = [] {
  std::array<Regime, kBitCombinations> table{};
  for (std::size_t b = 0; b < table.size(); ++b) table[b] = regime_of(static_cast<std::uint8_t>(b));
  return table;
}();

/// One step of the median tracker m of |r|: up by e^η when |r| > m, down by e^{−η} otherwise; it settles
/// where |r| exceeds m half the time. The exact median of a warm-up's residuals starts it (track_noise).
double track_median(double m, double a) noexcept {
  // The factor by table look-up, not a branch: |r| > m is a coin toss once m has settled, which a
  // conditional jump would mispredict half the time.
  static constexpr std::array<double, 2> kStep{kTrackDown, kTrackUp};
  return m * kStep[static_cast<std::size_t>(a > m)];
}

/// One residual |r| of quantity q (§13, "Noise"). A median of zero (nothing seen, or mostly exact zeros)
/// stays so on a zero residual; a nonzero one starts a warm-up: the next kNoiseWarmUp residuals, zeros
/// included, inserted into an ascending buffer, m the median of those taken so far — the lower middle one of
/// an even count (a transient only inflates |r|: the lower one is robust to one more of them). Once warmed up,
/// the tracker steps m from there (a median of zero waits for the next nonzero residual).
double track_noise(RegimeState& s, std::size_t q, double a) noexcept {
  int& left = s.noise_warm_up_left[q];
  const double m = s.noise_median_pu[q];
  if (left == 0) {
    if (m != 0.0) return track_median(m, a);
    if (!(a > 0.0)) return m;
    left = kNoiseWarmUp;
  }
  std::array<double, kNoiseWarmUp>& sorted = s.noise_warm_up_pu[q];
  const int taken = kNoiseWarmUp - left;
  int k = taken;
  for (; k > 0 && sorted[static_cast<std::size_t>(k - 1)] > a; --k)
    sorted[static_cast<std::size_t>(k)] = sorted[static_cast<std::size_t>(k - 1)];
  sorted[static_cast<std::size_t>(k)] = a;
  --left;
  return sorted[static_cast<std::size_t>(taken / 2)];  // taken + 1 residuals: the (lower) middle one
}

/// Two doubles as one GCC vector: its comparisons give a lane mask and `?:` selects by it, one source that
/// g++ and clang compile to packed SSE2 on x86-64 (NEON on aarch64, scalar code elsewhere) — branch-free,
/// where Eigen's select() evaluates element by element with a conditional jump each. A comparison is the
/// scalar comparison per lane (false where either side is NaN; ±0 equal).
using Lanes = double __attribute__((vector_size(16)));
static_assert(sizeof(Lanes) == sizeof(Vec2), "a Vec2 is two packed doubles");

[[gnu::always_inline]] inline Lanes lanes(const Vec2& v) noexcept {
  Lanes l;
  std::memcpy(&l, v.data(), sizeof l);  // one 16-byte load
  return l;
}
[[gnu::always_inline]] inline Vec2 vec(const Lanes& l) noexcept {
  Vec2 v;
  std::memcpy(v.data(), &l, sizeof l);
  return v;
}

/// Per lane, a > b ? x : y.
[[gnu::always_inline]] inline Vec2 select_greater(const Vec2& a, const Vec2& b, const Vec2& x, const Vec2& y) noexcept {
  return vec(lanes(a) > lanes(b) ? lanes(x) : lanes(y));
}

/// track_median on two quantities at once (u and i), each lane as the scalar form steps it: the same
/// factor, the same product (the pair is one packed operation where a scalar step was one each).
[[gnu::always_inline]] inline Vec2 track_medians(const Vec2& m, const Vec2& a) noexcept {
  return m.cwiseProduct(select_greater(a, m, Vec2::Constant(kTrackUp), Vec2::Constant(kTrackDown)));
}

/// The smallest nonzero |change| of two quantities at once (u and i): q = min(q, a > 0 ? a : q) per lane.
[[gnu::always_inline]] inline Vec2 track_resolutions(const Vec2& q, const Vec2& a) noexcept {
  return q.cwiseMin(select_greater(a, Vec2::Zero(), a, q));
}

/// The smallest nonzero |change|; whether it became smaller.
bool track_resolution(double& q, double change) noexcept {
  const double a = std::abs(change), before = q;
  q = std::min(q, a > 0.0 ? a : q);
  return q < before;
}

/// A sample far from the previous one: the change of operating point between them excited a transient
/// that has decayed to e^{−Δt/τ_el} of |Δi| (τ_el the slowest the model admits). Steady if that remnant is
/// within the current's noise (its own estimate's noise, 2·decay²·σ_i², included). `dt_over_tau` = Δt/τ_el,
/// `z_sq_var_i` = z²·σ_i². Out of line: the exp() call would otherwise make the common path spill.
[[gnu::noinline]] std::uint8_t standalone_transient(double dt_over_tau, const Vec2& di, double z_sq_var_i) noexcept {
  const double decay = std::exp(-dt_over_tau);
  const Vec2 remnant = decay * di.cwiseAbs();
  const double bound = z_sq_var_i * (1.0 + 2.0 * decay * decay);
  return remnant.squaredNorm() > 0.0 && remnant.cwiseProduct(remnant).maxCoeff() > bound ? regime_bit::kTransient : 0;
}

/// Whether window m's flux leaves both a's and b's on one side: each difference beyond what the configuration's
/// tolerance does over the operating points' difference (and stated speed errors), by more than z·σ of the difference.
bool flux_leaves_both(const WindowFlux& m, const WindowFlux& a, const WindowFlux& b, const RegimeNoise& noise,
                      const RegimeConfig& c, double slope_reach, double z_sq) noexcept {
  const double var_m = m.variance(noise);
  const auto side = [&](const WindowFlux& o) {
    const double d = m.psi_pu - o.psi_pu;
    const double reach = c.dr_pu * std::abs(m.lever_r - o.lever_r) + c.dx_d_pu * std::abs(m.lever_x_d - o.lever_x_d) +
                         slope_reach * (std::abs(m.lever_x_q) + std::abs(o.lever_x_q)) + (m.bias_pu + o.bias_pu);
    const double excess = std::abs(d) - reach;
    const bool beyond = excess > 0.0 && excess * excess > z_sq * (var_m + o.variance(noise));
    return beyond ? (d > 0.0 ? 1 : -1) : 0;
  };
  const int left = side(a);
  return left != 0 && left == side(b);
}

/// learn()'s noise medians while a quantity warms up or a nonzero residual meets a zero median (which starts
/// a warm-up): each quantity's residuals in their order, d then q. Out of line: the common path stays as small as it was.
[[gnu::noinline]] void learn_noise_warming(RegimeState& s, const Vec2& ru, const Vec2& ri, double rn) noexcept {
  std::array<double, 3>& m = s.noise_median_pu;
  m[0] = track_noise(s, 0, ru[0]);
  m[0] = track_noise(s, 0, ru[1]);
  m[1] = track_noise(s, 1, ri[0]);
  m[1] = track_noise(s, 1, ri[1]);
  m[2] = track_noise(s, 2, rn);
}

/// Learns a sample's noise and resolution from the chain and takes it in as the chain's last. Returns
/// whether a measured resolution changed. u's and i's trackers run as one pair (d's change first, then
/// q's: a minimum does not depend on the order, a median tracker's two steps keep theirs).
bool learn(RegimeState& s, const RegimeInput& in, double t_s, double w) noexcept {
  bool resolution_changed = false;
  const Vec2 u_reported = in.u_reported_pu.allFinite() ? in.u_reported_pu : in.u_pu;
  const Vec2 i_reported = in.i_reported_pu.allFinite() ? in.i_reported_pu : in.i_pu;
  if (s.points >= 1) {
    const Vec2 du = (u_reported - s.u_reported_pu).cwiseAbs(), di = (i_reported - s.i_reported_pu).cwiseAbs();
    const Vec2 before(s.measured_resolution_pu[0], s.measured_resolution_pu[1]);
    const Vec2 q = track_resolutions(track_resolutions(before, Vec2(du[0], di[0])), Vec2(du[1], di[1]));
    s.measured_resolution_pu[0] = q[0];
    s.measured_resolution_pu[1] = q[1];
    resolution_changed =
        (q[0] < before[0]) | (q[1] < before[1]) | track_resolution(s.measured_resolution_pu[2], in.n_pu - s.n_pu[0]);
  }
  // Only a chain's samples are close enough for their second difference to be noise: a standalone
  // sample's neighbours are other operating points.
  const bool chain = in.timing == SampleTiming::kDense || in.timing == SampleTiming::kContiguous;
  const double span = t_s - s.t_s[1];
  if (s.points == 2 && chain && s.chained >= 1 && span > 0.0) {
    // The middle sample against the line through its neighbours, r = x₁ − (w·x₂ + (1 − w)·x₀) with
    // w = (t₁ − t₀)/(t₂ − t₀) (step() divides it beside the slope's 1/Δt): zero for a ramp at any
    // spacing; for white noise of σ its variance is σ²·(1 + w² + (1 − w)²) = σ²·(3/2 + 2·d),
    // d = (w − ½)² ∈ [0, ¼], whose root the factor removes:
    // (3/2 + 2d)^{−½} ≈ 0.81650 − 0.53215·d + 0.37763·d², within 2e-4 (no square root per sample).
    const double d = (w - 0.5) * (w - 0.5);
    const double norm = 0.81649658 + d * (-0.53215 + d * 0.37763);
    const Vec2 ru = norm * (s.u_pu[0] - (w * in.u_pu + (1.0 - w) * s.u_pu[1])).cwiseAbs();
    const Vec2 ri = norm * (s.i_pu[0] - (w * in.i_pu + (1.0 - w) * s.i_pu[1])).cwiseAbs();
    const double rn = norm * std::abs(s.n_pu[0] - (w * in.n_pu + (1.0 - w) * s.n_pu[1]));
    std::array<double, 3>& m = s.noise_median_pu;
    const std::array<int, 3>& left = s.noise_warm_up_left;
    // A zero median stepped is zero: on zero residuals (a constant quantity) it stays on this path.
    const bool start =
        ((m[0] == 0.0) & (ru[0] + ru[1] > 0.0)) | ((m[1] == 0.0) & (ri[0] + ri[1] > 0.0)) | ((m[2] == 0.0) & (rn > 0.0));
    if (((left[0] | left[1] | left[2]) != 0) | start) [[unlikely]] {
      learn_noise_warming(s, ru, ri, rn);
    } else {
      const Vec2 ui = track_medians(track_medians(Vec2(m[0], m[1]), Vec2(ru[0], ri[0])), Vec2(ru[1], ri[1]));
      m[0] = ui[0];
      m[1] = ui[1];
      m[2] = track_median(m[2], rn);
    }
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
  s.u_reported_pu = u_reported;
  s.i_reported_pu = i_reported;
  if (s.points < 2) ++s.points;
  s.chained = chain ? std::min(s.chained + 1, 2) : 0;
  return resolution_changed;
}

}  // namespace

std::uint64_t RegimeCounts::total() const noexcept {
  std::uint64_t s = 0;
  for (std::uint64_t c : n) s += c;
  return s;
}

std::uint64_t RegimeCounts::excluded() const noexcept {
  std::uint64_t s = 0;
  for (const RegimeInfo& r : kRegimes) s += r.excluded ? (*this)[r.regime] : 0;
  return s;
}

double chi2_bound(double z) noexcept { return -2.0 * std::log(std::erfc(z / std::sqrt(2.0))); }

RegimeClassifier::RegimeClassifier(const RegimeConfig& config) noexcept {
  reconfigure(config);
  reset();
}

void RegimeClassifier::reconfigure(const RegimeConfig& config) noexcept {
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
  k.flux_q = Vec2(0.0, c.psi_max_pu);
  k.x_max = std::max(c.x_d_pu, c.x_q_pu);
  k.dx_max = std::max(c.dx_d_pu, c.dx_q_pu);
  k.cos_angle = 1.0 / std::sqrt(1.0 + c.tan_angle * c.tan_angle);
  k.sin_angle = c.tan_angle * k.cos_angle;
  k.cos_hall = c.hall_frame_error_rad > 0.0 ? std::cos(c.hall_frame_error_rad) : -1.0;
  // A sensorless frame's error within the cone at least (a = 0): ψ_max·√(2·(1 − cos δ_tol)), or within the Hall
  // sensors' error where that is smaller.
  const double cos_least = std::max(k.cos_angle, k.cos_hall);
  k.frame_least_pu = c.sensorless ? c.psi_max_pu * std::sqrt(2.0 * (1.0 - cos_least)) : 0.0;
  k.slope_reach = k.inv_omega_n * (c.x_q_pu + c.dx_q_pu);
  k.frame_reach_pu = c.sensorless ? 0.5 * c.psi_max_pu * (1.0 - k.cos_angle) : 0.0;
  // Neighbours formed with the old constants are no neighbours of a window formed with the new ones.
  state_.flux_previous.valid = state_.flux_reference.valid = false;
  update_quantisation();
}

void RegimeClassifier::reset() noexcept {
  state_ = RegimeState{};
  state_.measured_resolution_pu.fill(kInf);
  noise_ = RegimeNoise{};
  update_quantisation();
}

void RegimeClassifier::update_quantisation() noexcept {
  for (std::size_t q = 0; q < 3; ++q) {
    const double measured = state_.measured_resolution_pu[q] < kInf ? state_.measured_resolution_pu[q] : 0.0;
    const double res = config_.resolution_pu[q] > 0.0 ? config_.resolution_pu[q] : measured;
    quantisation_var_[q] = res * res * (1.0 / 12.0);  // a uniform quantisation error has variance q²/12
  }
}

RegimeNoise RegimeClassifier::current_noise() const noexcept {
  const auto variance = [this](std::size_t q) {
    const double sigma = state_.noise_median_pu[q] * kSigmaPerMedian;
    return sigma * sigma + quantisation_var_[q];
  };
  return {variance(0), variance(1), variance(2)};
}

/// What step() derives once from the sample and the chain for every test. The tests take these as locals,
/// not back from the state step() has just stored them in (each such load would wait on its store, on the
/// path from 1/Δt's division to every test).
struct RegimeClassifier::Terms {
  double dt_s = 0.0;          ///< from the chain's last window centre
  Vec2 slope = Vec2::Zero();  ///< the current's slope this sample's correction takes [pu/s]
  Vec2 previous_slope = Vec2::Zero();
  double inv_dt = 0.0, previous_inv_dt = 0.0;
  /// n²·x_q², n²·x_d² as every test forms them (n²·x·x), as one pair; and the voltage noise of a row, d and q
  /// (the transient test's rows and ψm's noise begin with it): σ_u² + (r² + n²·x_o²)·σ_i².
  Vec2 n2_x2 = Vec2::Zero();
  Vec2 row_noise = Vec2::Zero();
  /// B_d + tan δ_tol·B_q: what the configuration's uncertainty puts into the lock test's margin (lock_bits).
  double lock_bias = 0.0;
};

std::uint8_t RegimeClassifier::bridge_bits(const RegimeInput& in) const noexcept {
  const RegimeConfig& c = config_;
  const RegimeNoise& v = noise_;
  const double n = in.n_pu, n2 = n * n;
  // Bridge off: the reported voltage and the current are zero within their noise where a modulating bridge
  // could not hold a zero current: with |u| inside the voltage's zero band √c₂·σ_u the machine would carry
  // |i| = |M⁻¹·(u − e)| ≥ (|n|·ψ_min − √c₂·σ_u)/‖M‖, ‖M‖ ≤ ‖M‖_F = √(2·r² + n²·(x_d² + x_q²)) at D_M's largest r,
  // beyond the current's zero band √c₂·σ_i.
  if (in.u_reported_sq_pu <= c.chi2 * v.u_sq && in.i_pu.squaredNorm() <= c.chi2 * v.i_sq) [[unlikely]] {
    const double r = k_.r_max;
    const double emf_margin = std::abs(n) * c.psi_min_pu - std::sqrt(c.chi2 * v.u_sq);
    const double m_sq = 2.0 * r * r + n2 * (c.x_d_pu * c.x_d_pu + c.x_q_pu * c.x_q_pu);
    if (emf_margin > 0.0 && emf_margin * emf_margin > c.chi2 * v.i_sq * m_sq) return regime_bit::kBridgeOff;
  }
  return 0;
}

double RegimeClassifier::lock_variance(const RegimeInput& in, const Terms& t) const noexcept {
  const RegimeConfig& c = config_;
  const Constants& k = k_;
  const RegimeNoise& v = noise_;
  const Vec2& i = in.i_pu;
  const double slope_sq = 2.0 * t.inv_dt * t.inv_dt;  // Var(s) per σ_i²
  const double var_d =
      v.u_sq + (k.r_sq + t.n2_x2[0] + k.slope_var_x_sq[0] * slope_sq) * v.i_sq + c.x_q_pu * c.x_q_pu * i[1] * i[1] * v.n_sq;
  const double flux_q = c.psi_max_pu + c.x_d_pu * std::abs(i[0]);
  const double var_q = v.u_sq + (k.r_sq + t.n2_x2[1] + k.slope_var_x_sq[1] * slope_sq) * v.i_sq + flux_q * flux_q * v.n_sq;
  return var_d + c.tan_angle * c.tan_angle * var_q;
}

std::uint8_t RegimeClassifier::lock_bits(const RegimeInput& in, Terms& t) const noexcept {
  const RegimeConfig& c = config_;
  const Constants& k = k_;
  const RegimeNoise& v = noise_;
  const Vec2& i = in.i_pu;
  const double n = in.n_pu, n2 = n * n, abs_n = std::abs(n);
  const Vec2 abs_i = i.cwiseAbs();
  // Angle locked: e, what the model leaves to the magnet, lies in the cone of half-angle δ_tol about
  // sgn(n)·q, widened by what the configuration's uncertainty (r within D_M, x within its tolerance) and
  // the noise can put there. Independent of ψm's magnitude. Both axes at once: (d, q) in one vector.
  const Vec2& sl = t.slope;
  const Vec2 abs_sl = sl.cwiseAbs();
  const Vec2 rotation = (n * k.x_swapped).cwiseProduct(i.reverse()).cwiseProduct(Vec2(1.0, -1.0));  // −n·J·x·i
  const Vec2 e = ((in.u_pu - c.r_pu * i) - k.x_over_omega_n.cwiseProduct(sl)) + rotation;
  const Vec2 b =
      (c.dr_pu * abs_i + (abs_n * k.dx_swapped).cwiseProduct(abs_i.reverse())) + k.dx_over_omega_n.cwiseProduct(abs_sl);
  t.lock_bias = b[0] + c.tan_angle * b[1];
  // The speed's sign where it stands out of its noise; else either direction of q.
  const double along = n2 > k.z_sq * v.n_sq ? (n > 0.0 ? e[1] : -e[1]) : std::abs(e[1]);
  const double lock = std::abs(e[0]) - c.tan_angle * (along + b[1]) - b[0];
  if (lock > 0.0) [[unlikely]] {
    if (lock * lock > k.z_sq * lock_variance(in, t)) return regime_bit::kNotLocked;
  }
  return 0;
}

double RegimeClassifier::frame_flux(const RegimeInput& in, const Terms& t) const noexcept {
  const RegimeConfig& c = config_;
  const Constants& k = k_;
  // The largest frame error the lock test passes: e = n·ψ·[sin δ, cos δ] hides while sin(δ − δ_tol) ≤ a, a =
  // cos δ_tol·(B_d + tan δ_tol·B_q + z·σ_L)/(|n|·ψ_min); a frame turning with the rotor is within δ_tol + π/2
  // (a ≥ 1: the test cannot judge it). Against the model's [0, n·ψ̂] it adds |n|·ψ·|[sin δ, cos δ − 1]| =
  // |n|·ψ·2·sin(δ/2) to the magnet's voltage error: at most ψ_max·√(2·(1 − cos δ_max)) per unit of speed.
  const double reach = k.cos_angle * (t.lock_bias + std::sqrt(k.z_sq * lock_variance(in, t)));
  const double emf = std::abs(in.n_pu) * c.psi_min_pu;
  const double a = reach < emf ? reach / emf : 1.0;
  double cos_max = k.cos_angle * std::sqrt(1.0 - a * a) - k.sin_angle * a;
  // Below their speed, Hall sensors put the frame within their own error of the rotor's: the smaller bound holds.
  if (std::abs(in.n_pu) < c.hall_below_n_pu) cos_max = std::max(cos_max, k.cos_hall);
  return c.psi_max_pu * std::sqrt(2.0 * (1.0 - cos_max));
}

std::uint8_t RegimeClassifier::contiguous_transient_bits(const RegimeInput& in, const Terms& t) noexcept {
  const Constants& k = k_;
  const RegimeNoise& v = noise_;
  RegimeState& s = state_;
  // Consecutive windows: what the steady state and the inductive correction (the slope between window
  // centres) leave out, per row (d, q) in voltage:
  //   (x/ω_n)·|s_k − s_{k−1}|   the slope changed: the correction is exact only for a ramp
  //   (Δx/ω_n)·|s_k|            the inductance's tolerance on the correction
  //   x_o·|Δn|·|Δi_o|/4          mean(n·x·i) − n̄·x·ī, bounded by the ranges' product over 4
  // against the row's noise and the slope change's own noise.
  const double dn = std::abs(in.n_pu - s.n_pu[0]);
  const Vec2 di = (in.i_pu - s.i_pu[0]).cwiseAbs();
  Vec2 term = k.inv_omega_n * k.dx.cwiseProduct(t.slope.cwiseAbs()) + (0.25 * dn) * k.x_swapped.cwiseProduct(di.reverse());
  double slope_noise_sq = 0.0;  // Var(s_k − s_{k−1}) per σ_i²
  if (s.previous_slope_valid) {
    term += k.inv_omega_n * k.x.cwiseProduct((t.slope - t.previous_slope).cwiseAbs());
    const double a = t.inv_dt, p = t.previous_inv_dt;
    slope_noise_sq = a * a + (a + p) * (a + p) + p * p;
  }
  const double slope_var = k.inv_omega_n_sq * slope_noise_sq * v.i_sq;
  const Vec2 row = t.row_noise + k.x_sq * slope_var;  // σ² of the rows d and q
  const Vec2 term_sq = term.cwiseProduct(term), bound = k.z_sq * row;
  const bool own = (term_sq[0] > bound[0]) | (term_sq[1] > bound[1]);
  // A slope change shows only once both windows around the junction are in: the window after one is
  // corrected with a slope that straddles it.
  const bool transient = own || s.previous_transient;
  s.previous_transient = own;
  return transient ? regime_bit::kTransient : 0;
}

// A window's flux against its neighbours (§13, "… inside one window"). A release and a take-over both inside one
// window leave its means m times the modulating ones where the drive reports zeros while off: the flux reads m·ψm,
// which no test of the window alone tells from a machine with that flux, but its neighbours do. The steady state mixed
// over a window (a load changed inside it, a ramp) is linear in u, i at the window's speed, so its flux lies between
// its neighbours' but for what Δr and Δx do over the operating points' difference. A window whose flux leaves both
// on one side beyond that and the noise is mixed with something the model does not describe: judged one window late,
// against this window and the last one before it not found mixed. Only windows admitted as exciting ψm take part.
std::uint8_t RegimeClassifier::flux_excursion_bits(const RegimeInput& in, const Terms& t, std::uint8_t bits) noexcept {
  RegimeState& s = state_;
  // A chain's first window (after a gap) adapts nothing and is never judged, but it is the next one's left neighbour.
  const bool chained = in.timing == SampleTiming::kContiguous || in.timing == SampleTiming::kFirst;
  const bool candidate = in.window_s > 0.0 && chained && s.noise_known && (bits & regime_bit::kExcluded) == 0 &&
                         (bits & regime_bit::kExcitesPsiM) != 0;
  if (!candidate) {
    s.flux_previous.valid = s.flux_reference.valid = false;
    return 0;
  }
  WindowFlux here = window_flux(in, t);
  // A median still warming up is the median of a few residuals (§13, "Start (warm-up)"): no window entering then is
  // judged on it.
  here.settled = (s.noise_warm_up_left[0] | s.noise_warm_up_left[1] | s.noise_warm_up_left[2]) == 0;
  const WindowFlux& judged = s.flux_previous;
  const bool mixed = judged.valid && judged.settled && s.flux_reference.valid &&
                     flux_leaves_both(judged, s.flux_reference, here, s.flux_noise, config_, k_.slope_reach, k_.z_sq);
  if (!mixed) s.flux_reference = s.flux_previous;
  s.flux_previous = here;
  s.flux_noise = noise_;
  return mixed ? regime_bit::kPreviousMixed : 0;
}

WindowFlux RegimeClassifier::window_flux(const RegimeInput& in, const Terms& t) const noexcept {
  const RegimeConfig& c = config_;
  const Constants& k = k_;
  const Vec2& i = in.i_pu;
  const double n = in.n_pu, inv_n = 1.0 / n, inv_n_sq = inv_n * inv_n;
  RPEM_ASSERT(n != 0.0, "a window that excites ψm turns");
  const double slope_q = t.slope[1];
  WindowFlux f;
  f.psi_pu = (in.u_pu[1] - c.r_pu * i[1] - k.x_over_omega_n[1] * slope_q - n * c.x_d_pu * i[0]) * inv_n;
  // Noise: u's; i_q's through r and the slope a·(i_k − i_{k−1}), a = x_q/(ω_n·Δt), whose difference from a neighbour's
  // holds (r + 2a)²·σ_i² + (r + a)²·σ_i² + a²·σ_i² = 2·(r² + 3·a·(r + a))·σ_i², half to each; i_d's through n·x_d; and
  // the speed's through the flux (§13, "A freewheel inside one window").
  const double flux_q = c.psi_max_pu + c.x_d_pu * std::abs(i[0]);
  const double flux_q_sq = flux_q * flux_q;
  const double a = k.x_over_omega_n[1] * t.inv_dt;
  f.var_per_u = inv_n_sq;
  f.var_per_i = (k.r_sq + 3.0 * a * (c.r_pu + a) + t.n2_x2[1]) * inv_n_sq;
  f.var_per_n = flux_q_sq * inv_n_sq;
  f.var_stated_pu = flux_q_sq * (in.n_error_noise_pu * in.n_error_noise_pu) * inv_n_sq;
  f.bias_pu = flux_q * std::abs(in.n_error_pu * inv_n) + k.frame_reach_pu;
  f.lever_r = i[1] * inv_n;
  f.lever_x_d = i[0];
  f.lever_x_q = slope_q * inv_n;
  f.valid = true;
  return f;
}

// A speed off by up to E (a tracker's reads rebuilt to the window's mean, §13 "Speed at the read", "… where the
// acceleration changes"): the steady state's speed terms n·(−x_q·i_q, x_d·i_d + ψm) are then off by up to
// E·(x_q·|i_q|, x_d·|i_d| + ψ_max), which the inductive correction and the slope terms do not see where the current
// holds (a stop at constant current). Against the row's noise with the speed's own and E's (the reads' changes of
// acceleration around the window) through the same coefficients: an E within them (reads jittering at a crawl) is
// not told from noise.
std::uint8_t RegimeClassifier::speed_error_bits(const RegimeInput& in, const Terms& t) const noexcept {
  const Vec2 coeff = k_.x_swapped.cwiseProduct(in.i_pu.cwiseAbs().reverse()) + k_.flux_q;
  const Vec2 coeff_sq = coeff.cwiseProduct(coeff);
  const Vec2 term_sq = (in.n_error_pu * in.n_error_pu) * coeff_sq;
  const double speed_var = noise_.n_sq + in.n_error_noise_pu * in.n_error_noise_pu;
  const Vec2 bound = k_.z_sq * (t.row_noise + speed_var * coeff_sq);
  return (term_sq[0] > bound[0]) | (term_sq[1] > bound[1]) ? regime_bit::kTransient : 0;
}

std::uint8_t RegimeClassifier::excitation_bits(const RegimeInput& in, const Terms& t) const noexcept {
  const RegimeConfig& c = config_;
  const Constants& k = k_;
  const RegimeNoise& v = noise_;
  const Vec2& i = in.i_pu;
  const double n = in.n_pu, n2 = n * n, abs_n = std::abs(n);
  const Vec2 abs_i = i.cwiseAbs();
  const double i_sq = i.squaredNorm();
  std::uint8_t bits = 0;
  // Excitation: the parameter's term, at its smallest inside D_M, less what the other terms' uncertainty
  // can put in its place, against its noise as the estimator's averaging leaves it: h² = γ/(2 − γ) of
  // one sample's variance (an exponential filter of gain γ).
  const Vec2 h_sq = in.weight.array() / (2.0 - in.weight.array());  // ψm's and r_s' in one division of a pair
  const double psi_term = abs_n * c.psi_min_pu - c.dr_pu * abs_i[1] - abs_n * c.dx_d_pu * abs_i[0];
  if (psi_term > 0.0) {
    const double noise = t.row_noise[1] + k.psi_max_sq * v.n_sq;
    if (psi_term * psi_term > k.z_sq * h_sq[0] * noise) bits |= regime_bit::kExcitesPsiM;
  }
  // r_min·|i| must at least exceed |n|·Δψ (and a sensorless frame's least error): checked on the squares before
  // |i| is taken. A sensorless frame's possible error only where it is needed (three roots and a division). That
  // error's voltage acts at the speeds the window passed through, not only at its mean: where the frame wanders and
  // the rotor turns back inside the window its mean along the current is the power the motion took (§13).
  const double reach_n = std::max(abs_n, in.n_reach_pu);
  const double least = abs_n * c.dpsi_pu + reach_n * k.frame_least_pu;
  if (k.r_min_sq * i_sq > least * least) {
    const double i_abs = std::sqrt(i_sq);
    const auto term = [&](double frame) {
      return c.r_min_pu * i_abs - abs_n * (c.dpsi_pu + k.dx_max * i_abs) - reach_n * frame;
    };
    const double own = term(c.sensorless && reach_n > 0.0 ? frame_flux(in, t) : 0.0);
    if (own > 0.0) {
      const double flux = c.psi_max_pu + k.x_max * i_abs;
      const double noise = v.u_sq + (k.r_sq + n2 * k.x_max * k.x_max) * v.i_sq + flux * flux * v.n_sq;
      const double bound_sq = k.z_sq * h_sq[1] * noise;
      if (own * own > bound_sq) {
        bits |= regime_bit::kExcitesRs;
        // A sensor's frame only assumed: would a sensorless frame's possible error have kept the term down?
        if (c.angle_source_assumed && reach_n > 0.0) {
          const double sensorless = term(frame_flux(in, t));
          if (!(sensorless > 0.0 && sensorless * sensorless > bound_sq)) bits |= regime_bit::kRsOnAssumedFrame;
        }
      }
    }
  }
  return bits;
}

RegimeClassifier::Terms RegimeClassifier::take_slope(const RegimeInput& in, double dt_s) noexcept {
  RegimeState& s = state_;
  Terms t;
  t.dt_s = dt_s;
  // The current's slope: given (a block's end points), or between consecutive samples of a chain.
  t.previous_slope = s.slope_pu_s;
  t.previous_inv_dt = s.inv_dt;
  s.previous_slope_pu_s = t.previous_slope;
  s.previous_slope_valid = s.slope_valid;
  s.previous_inv_dt = t.previous_inv_dt;
  const bool linked =
      s.points >= 1 && dt_s > 0.0 && (in.timing == SampleTiming::kDense || in.timing == SampleTiming::kContiguous);
  t.inv_dt = linked ? 1.0 / dt_s : 0.0;
  if (!linked) {
    s.previous_transient = false;
  } else if (std::isnan(in.di_dt_pu_s[0])) {
    t.slope = (in.i_pu - s.i_pu[0]) * t.inv_dt;
  } else {
    t.slope = in.di_dt_pu_s;
  }
  s.inv_dt = t.inv_dt;
  s.slope_valid = linked;
  s.slope_pu_s = t.slope;
  return t;
}

Classification RegimeClassifier::step(const RegimeInput& in) noexcept {
  const RegimeConfig& c = config_;
  const Constants& k = k_;
  RegimeState& s = state_;
  if (!all_finite(in.u_pu, in.i_pu, in.n_pu, in.u_reported_sq_pu, in.window_s, in.weight)) [[unlikely]] {
    break_chain();
    return Classification::of(regime_bit::kInvalid);
  }
  if (in.timing == SampleTiming::kFirst) break_chain();
  if (!s.has_origin) [[unlikely]] {
    s.t_origin_ns = in.t_ns;
    s.has_origin = true;
  }
  // Times are window centres (a mean stands for its centre), relative to the first sample.
  const double t_s = to_seconds(in.t_ns - s.t_origin_ns) - 0.5 * in.window_s;
  const double w = (s.t_s[0] - s.t_s[1]) / (t_s - s.t_s[1]);  // learn()'s w = (t₁ − t₀)/(t₂ − t₀)
  Terms t = take_slope(in, s.points >= 1 ? t_s - s.t_s[0] : 0.0);

  noise_ = current_noise();
  const RegimeNoise& v = noise_;
  const double n2 = in.n_pu * in.n_pu;
  t.n2_x2 = (n2 * k.x_swapped).cwiseProduct(k.x_swapped);
  t.row_noise = Vec2::Constant(v.u_sq) + (Vec2::Constant(k.r_sq) + t.n2_x2) * v.i_sq;

  std::uint8_t bits = bridge_bits(in) | lock_bits(in, t);
  // A standalone sample's transient test calls exp(): judged last (below), so that across the call few values
  // are live and the common path keeps its values in registers.
  const bool standalone = in.timing == SampleTiming::kStandalone && s.points >= 1;
  const Vec2 i_before = s.i_pu[0];
  if (in.timing == SampleTiming::kContiguous && s.slope_valid) bits |= contiguous_transient_bits(in, t);
  if (in.n_error_pu > 0.0) bits |= speed_error_bits(in, t);
  bits |= excitation_bits(in, t);

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
  bits |= flux_excursion_bits(in, t, bits);
  if (learn(s, in, t_s, w)) [[unlikely]]
    update_quantisation();
  if (standalone) [[unlikely]]
    bits |= standalone_transient(t.dt_s / c.electrical_time_constant_s, in.i_pu - i_before, k.z_sq * v.i_sq);
  return {kRegimeOfBits[bits], bits};
}

void StreamClassifier::clear_sums() noexcept {
  count_ = 0;
  u_sum_.setZero();
  i_sum_.setZero();
  n_sum_ = u_reported_sum_ = 0.0;
}

void StreamClassifier::reset() noexcept {
  classifier_.reset();
  held_ = kUnclassified;  // until a chain's first sample is in: admitted
  has_start_ = false;
  clear_sums();
}

void StreamClassifier::reconfigure(const RegimeConfig& config) noexcept {
  classifier_.reconfigure(config);
  clear_sums();
}

Classification StreamClassifier::start(const RegimeInput& in) noexcept {
  held_ = classifier_.step(in);
  clear_sums();
  i_start_ = in.i_pu;
  start_ns_ = in.t_ns;
  has_start_ = held_.regime != Regime::kInvalid;
  return held_;
}

Classification StreamClassifier::close_block(std::int64_t t_ns, const Vec2& i_pu) noexcept {
  RPEM_ASSERT(count_ >= 1, "a block closes on the sample step_dense() has just added");
  if (!has_start_) {  // dense samples before any chain start (a caller's misuse): classified alone
    RegimeInput in;
    in.timing = SampleTiming::kFirst;
    in.t_ns = t_ns;
    in.u_pu = u_sum_ / count_;
    in.i_pu = i_pu;
    in.n_pu = n_sum_ / count_;
    in.u_reported_sq_pu = u_reported_sum_ / count_;
    return start(in);
  }
  // The block as one sample: the means, over the window from the previous block's last sample to its own,
  // whose current's slope its end points give exactly.
  const double inv_count = 1.0 / count_;
  RegimeInput b;
  b.timing = SampleTiming::kDense;
  b.t_ns = t_ns;
  b.window_s = to_seconds(t_ns - start_ns_);
  b.u_pu = u_sum_ * inv_count;
  b.i_pu = i_sum_ * inv_count;
  b.n_pu = n_sum_ * inv_count;
  b.u_reported_sq_pu = u_reported_sum_ * inv_count;
  RPEM_ASSERT(b.window_s >= 0.0, "dense samples come in time order (the conditioner resynchronises otherwise)");
  b.di_dt_pu_s = (i_pu - i_start_) / b.window_s;
  b.weight = (gain_rate_per_s_ * b.window_s).cwiseMin(1.0);  // the block's share of each estimate: its γ_L summed
  held_ = classifier_.step(b);
  clear_sums();
  i_start_ = i_pu;
  start_ns_ = t_ns;
  return held_;
}

}  // namespace rpem::core
