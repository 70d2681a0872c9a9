// Flux harmonics seen in the generated phase current. An isotropic machine (the Beckhoff configuration,
// L_d = L_q = L) under feed-forward voltage only (no PI) carries, for the rotor-frame term
// ψm·h·e^{jφ}·e^{±jnθ}, a stator-frame current of order ±n+1 obtained from u = R·i + L·di/dt + dψ/dt:
//   I_k = −j·k·ω·ψm·h·e^{jφ} / (R + j·k·ω·L),   k = n+1 (positive sequence) or −(n−1) (negative sequence).
// A DFT of the logged i_a against the true angle gives I_{n+1} at +(n+1)θ and conj(I_{−(n−1)}) at +(n−1)θ.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "case_fixtures.hpp"
#include "indep_drive/generator.hpp"

namespace indep {
namespace {

using C = std::complex<double>;

/// (2/N)·Σ i_a·e^{−j·order·θ} over the last whole electrical periods.
C dft(const Result& r, int order, std::size_t samples) {
  C sum;
  for (std::size_t k = r.log.size() - samples; k < r.log.size(); ++k) {
    sum += r.log[k].i_abc_A[0] * std::exp(C(0, -order * r.plant[k].theta_el_rad));
  }
  return 2.0 / static_cast<double>(samples) * sum;
}

void check_pair(const char* effect, int n) {
  Case c = testing::ideal_case("config/beckhoff-am8141.yaml");
  c.duration_s = 0.4;
  c.control.bandwidth_Hz = 0.0;  // feed-forward only
  enable_effects(c.effects, effect);
  const double rpm = 375.0;  // 25 Hz electrical with 4 pole pairs: 320 samples per electrical period at 8 kHz
  testing::hold(c, rpm, 0.0);
  const Result r = generate(c);
  const MachineParams& m = r.truth.true_machine;
  const HarmonicPair& h = n == 6 ? r.resolved.effects.flux_harmonic_6.pair : r.resolved.effects.flux_harmonic_12.pair;
  const double omega = rpm / 60 * 2 * kPi * m.pole_pairs;
  const std::size_t samples = 8 * 320;  // the last 0.32 s: eight whole electrical periods
  auto current = [&](int k, double hk, double phi) {
    return C(0, -k * omega) * m.psi_m_Wb * std::polar(hk, phi) / C(m.r_s_Ohm, k * omega * m.l_d_H);
  };
  const C hi = current(n + 1, h.h_hi_rel, h.phi_hi_rad);
  const C lo = current(-(n - 1), h.h_lo_rel, h.phi_lo_rad);
  const C got_hi = dft(r, n + 1, samples), got_lo = dft(r, n - 1, samples);
  EXPECT_NEAR(std::abs(got_hi - hi), 0.0, 0.01 * std::abs(hi))
      << effect << " order " << n + 1 << ": " << got_hi << " vs " << hi;
  EXPECT_NEAR(std::abs(got_lo - std::conj(lo)), 0.0, 0.01 * std::abs(lo))
      << effect << " order " << n - 1 << ": " << got_lo << " vs " << std::conj(lo);
  // No fundamental current: the feed-forward matches the (nominal) machine.
  EXPECT_LT(std::abs(dft(r, 1, samples)), 0.01 * std::abs(hi));
}

TEST(IndepFluxHarmonics, SixthAppearsAsFifthAndSeventhInThePhaseCurrent) { check_pair("flux_harmonic_6", 6); }
TEST(IndepFluxHarmonics, TwelfthAppearsAsEleventhAndThirteenthInThePhaseCurrent) { check_pair("flux_harmonic_12", 12); }

TEST(IndepFluxHarmonics, TruthGivesTheRotorFrameHarmonicOfTheFlux) {
  // The truth's d/q amplitudes and phases against a DFT of h(θ) over one electrical turn.
  const HarmonicPair p{6, 0.02, 0.4, 0.012, -0.9};
  HarmonicFlux h;
  h.add(p);
  C d, q;
  const int n = 4096;
  for (int k = 0; k < n; ++k) {
    const double theta = 2 * kPi * k / n;
    const Vec2 v = h.value(theta);
    d += v.x * std::exp(C(0, -6 * theta)) * (2.0 / n);
    q += v.y * std::exp(C(0, -6 * theta)) * (2.0 / n);
  }
  Case c = testing::ideal_case();
  c.duration_s = 0.001;
  c.effects.flux_harmonic_6 = {true, p};
  const EffectTruth t = *generate(c).truth.effect("flux_harmonic_6");
  // ψ_d,h = ψm·A_d·cos(6θ + φ_d) has DFT coefficient A_d·e^{jφ_d}.
  EXPECT_NEAR(std::abs(d), t.value("d_amplitude_rel"), 1e-12);
  EXPECT_NEAR(std::arg(d), t.value("d_phase_rad"), 1e-9);
  EXPECT_NEAR(std::abs(q), t.value("q_amplitude_rel"), 1e-12);
  EXPECT_NEAR(std::arg(q), t.value("q_phase_rad"), 1e-9);
  EXPECT_NEAR(t.value("back_emf_5_rel"), 5 * 0.02, 1e-15);
}

}  // namespace
}  // namespace indep
