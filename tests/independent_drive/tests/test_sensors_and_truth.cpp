// Sensor errors in the log against the plant, the machine draw, drifts, determinism and the truth file.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>

#include "case_fixtures.hpp"
#include "indep_drive/generator.hpp"

namespace indep {
namespace {

TEST(IndepSensors, LoggedCurrentsAndAngleCarryTheHiddenErrorsWithinOneQuantisationStep) {
  Case c = testing::ideal_case();
  c.duration_s = 0.5;
  c.sensors.adc_bits = 12;
  c.sensors.encoder_counts_per_rev = 4096;
  enable_effects(c.effects, "current_offset,current_gain,theta_offset");
  c.effects.current_offset.value = {0.0, 0.0, 0.12};
  c.effects.current_gain.value = {0.96, 1.0, 1.0};
  c.effects.theta_offset.offset_rad = 0.07;
  testing::hold(c, 250.0, 18.0);
  const Result r = generate(c);
  const double lsb = 2.0 * r.resolved.sensors.adc_full_scale_A / 4096.0;
  const double step_el = 2 * kPi / 4096 * c.machine.params.pole_pairs;
  for (std::size_t k = 0; k < r.log.size(); k += 7) {
    const std::array<double, 3> i = inverse_clarke(inverse_park(r.plant[k].i_A, r.plant[k].theta_el_rad));
    ASSERT_NEAR(r.log[k].i_abc_A[0], 0.96 * i[0], lsb / 2 + 1e-12) << k;
    ASSERT_NEAR(r.log[k].i_abc_A[1], i[1], lsb / 2 + 1e-12) << k;
    ASSERT_NEAR(r.log[k].i_abc_A[2], i[2] + 0.12, lsb / 2 + 1e-12) << k;
    // θ_true = θ_logged + offset_rad
    ASSERT_LE(std::abs(std::remainder(r.plant[k].theta_el_rad - r.log[k].theta_el_rad - 0.07, 2 * kPi)), step_el / 2 + 1e-9);
  }
  EXPECT_EQ(r.truth.effect("theta_offset")->value("offset_rad"), 0.07);
  EXPECT_EQ(r.truth.effect("current_offset")->labels.at(0).second, "c");
  EXPECT_EQ(r.truth.effect("current_offset")->value("offset_A"), 0.12);
  EXPECT_EQ(r.truth.effect("current_offset")->value("offset_a_A"), 0.0);
  EXPECT_EQ(r.truth.effect("current_gain")->value("gain_error"), 0.96 - 1.0);
  EXPECT_EQ(r.truth.effect("current_gain")->labels.at(0).second, "a");
}

TEST(IndepDraw, TrueMachineStaysWithinItsSpansAndIsIndependentOfTheEffects) {
  Case c = testing::machine_case();
  c.duration_s = 0.002;
  double lo = 1.0, hi = 1.0;
  for (std::uint64_t seed = 1; seed <= 60; ++seed) {
    c.seed = seed;
    c.effects = Effects{};
    const Result a = generate(c);
    const MachineParams& t = a.truth.true_machine;
    const MachineParams& m = c.machine.params;
    ASSERT_LE(std::abs(t.psi_m_Wb / m.psi_m_Wb - 1.0), 0.08);
    ASSERT_LE(std::abs(t.r_s_Ohm / m.r_s_Ohm - 1.0), 0.25);
    ASSERT_LE(std::abs(t.l_d_H / m.l_d_H - 1.0), 0.05);
    ASSERT_LE(std::abs(t.l_q_H / m.l_q_H - 1.0), 0.05);
    lo = std::min(lo, t.r_s_Ohm / m.r_s_Ohm);
    hi = std::max(hi, t.r_s_Ohm / m.r_s_Ohm);
    enable_effects(c.effects, "deadtime,delay,flux_harmonic_6,iron_loss");
    const Result b = generate(c);
    ASSERT_EQ(b.truth.true_machine.psi_m_Wb, t.psi_m_Wb);
    ASSERT_EQ(b.truth.true_machine.r_s_Ohm, t.r_s_Ohm);
  }
  EXPECT_LT(lo, 0.85);  // the draws use the span
  EXPECT_GT(hi, 1.15);
  c.draw.psi_m_rel = -0.05;
  EXPECT_DOUBLE_EQ(generate(c).truth.true_machine.psi_m_Wb, 0.95 * c.machine.params.psi_m_Wb);
}

TEST(IndepDraw, SameCaseSameLogOtherSeedOtherLog) {
  Case c = testing::machine_case();
  c.duration_s = 0.05;
  enable_effects(c.effects, "deadtime");
  const Result a = generate(c), b = generate(c);
  ASSERT_EQ(a.log.size(), 400u);
  for (std::size_t k = 0; k < a.log.size(); ++k) ASSERT_EQ(a.log[k].i_abc_A, b.log[k].i_abc_A);
  c.seed = 2;
  EXPECT_NE(generate(c).log.back().i_abc_A, a.log.back().i_abc_A);
}

TEST(IndepDrift, ResistanceAndMagnetFollowTheirTemperatures) {
  Case c = testing::ideal_case();
  c.duration_s = 0.5;
  enable_effects(c.effects, "rs_drift,psim_drift");
  c.thermal.winding = {30.0, 90.0, 0.2};
  c.thermal.magnet = {30.0, 70.0, 0.3};
  const Result r = generate(c);
  const PlantRow& last = r.plant.back();
  const double tw = 90.0 - 60.0 * std::exp(-last.t_s / 0.2), tm = 70.0 - 40.0 * std::exp(-last.t_s / 0.3);
  EXPECT_NEAR(last.T_winding_C, tw, 1e-9);
  EXPECT_NEAR(last.r_s_Ohm, c.machine.params.r_s_Ohm * (1.0 + 0.00393 * (tw - 30.0)), 1e-12);
  EXPECT_NEAR(last.psi_m_Wb, c.machine.params.psi_m_Wb * (1.0 - 0.001 * (tm - 30.0)), 1e-12);
  EXPECT_NEAR(r.log.back().T_magnet_C, tm, 1e-9);
  const EffectTruth& rs = *r.truth.effect("rs_drift");
  EXPECT_EQ(rs.value("coeff_per_K"), 0.00393);
  EXPECT_NEAR(rs.value("temperature_span_K"), 60.0 * (1.0 - std::exp(-0.5 / 0.2)), 1e-9);
}

TEST(IndepTruth, JsonCarriesMachinesSeedNoiseAndEveryEffect) {
  Case c = testing::machine_case();
  c.seed = 42;
  c.duration_s = 0.3;
  for (const EffectEntry& e : effect_catalogue()) enable_effects(c.effects, e.name);
  const Result r = generate(c);
  const nlohmann::json j = nlohmann::json::parse(truth_json(r.truth));
  EXPECT_EQ(j["seed"], 42);
  for (const char* key : {"psi_m_Wb", "r_s_Ohm", "l_d_H", "l_q_H", "pole_pairs"}) {
    EXPECT_TRUE(j["configured_machine"].contains(key)) << key;
    EXPECT_TRUE(j["true_machine"].contains(key)) << key;
  }
  EXPECT_EQ(j["effect_names"].size(), effect_catalogue().size());
  for (const EffectEntry& e : effect_catalogue()) EXPECT_TRUE(j["effects"].contains(e.name)) << e.name;
  EXPECT_TRUE(j["effects"]["deadtime"].contains("t_dead_s"));
  EXPECT_TRUE(j["effects"]["delay"].contains("delay_s"));
  EXPECT_TRUE(j["effects"]["theta_offset"].contains("offset_rad"));
  EXPECT_TRUE(j["effects"]["current_offset"].contains("offset_A"));
  EXPECT_TRUE(j["effects"]["current_gain"].contains("gain"));
  EXPECT_TRUE(j["effects"]["flux_harmonic_6"].contains("d_amplitude_rel"));
  EXPECT_TRUE(j["effects"]["lq_saturation"].contains("l_qq_ratio"));
  EXPECT_TRUE(j["effects"]["cross_saturation"].contains("l_dq_H"));
  EXPECT_TRUE(j["effects"]["rs_drift"].contains("coeff_per_K"));
  EXPECT_TRUE(j["noise"].contains("current_noise_A"));
  EXPECT_GT(j["effects"]["rs_drift"]["temperature_span_K"].get<double>(), 1.0);  // a drift gets a trajectory
}

TEST(IndepCatalogue, NamesAndKeysAreCheckedWithClearErrors) {
  Effects e;
  try {
    enable_effects(e, "deadtime,dead_time");
    FAIL();
  } catch (const std::invalid_argument& x) {
    EXPECT_NE(std::string(x.what()).find("unknown effect 'dead_time' (known: deadtime, delay"), std::string::npos)
        << x.what();
  }
  EXPECT_TRUE(e.deadtime.on);
  Case c = testing::machine_case();
  EXPECT_THROW(set_parameter(c, "deadtime.t_deadtime", 1.0), std::invalid_argument);
  EXPECT_THROW(set_parameter(c, "sensors.adc_bits", 12.5), std::invalid_argument);
  set_parameter(c, "delay.periods", 2.0);
  c.effects.delay.on = true;
  EXPECT_DOUBLE_EQ(resolve_defaults(c).effects.delay.delay_s, 2.0 / 8000.0);
  c.effects.delay.periods = 4.5;
  EXPECT_THROW(resolve_defaults(c), std::invalid_argument);
}

TEST(IndepCatalogue, DrawnEffectParametersStayInTheirRanges) {
  Case c = testing::machine_case();
  for (const EffectEntry& e : effect_catalogue()) enable_effects(c.effects, e.name);
  for (std::uint64_t seed = 1; seed <= 50; ++seed) {
    Case d = c;
    d.seed = seed;
    draw_effect_parameters(d);
    ASSERT_GE(d.effects.delay.periods, 1.0);
    ASSERT_LT(d.effects.delay.periods, 4.0);
    ASSERT_GE(d.effects.deadtime.t_dead_s, 0.5e-6);
    ASSERT_LE(std::abs(d.effects.theta_offset.offset_rad), 6 * kPi / 180 + 1e-12);
    ASSERT_GE(d.thermal.winding.end_C - d.thermal.winding.start_C, 30.0);
  }
}

}  // namespace
}  // namespace indep
