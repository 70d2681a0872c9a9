// The supervisor as a whole (supervisor.hpp, docs/supervisor.md): which temperatures an estimate gives
// (fused with the thermal model, else raw while valid), I_max from the last accepted estimate aged to
// the moment asked, the floor when nothing is trusted — a forged or replayed cold magnet never lifts
// it — and the configuration file.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "rpem/io/errors.hpp"
#include "rpem/supervisor/config.hpp"
#include "rpem/supervisor/supervisor.hpp"
#include "signed_estimate.hpp"
#include "support/temp_file.hpp"

namespace rpem::supervisor {
namespace {

using test::kT0;

/// examples/supervisor/supervisor.yaml's values.
Config config() {
  Config c;
  c.rated_current_A = 120.0;
  c.magnet = PartLimits{100.0, 140.0, 30.0, 4.0, 0.05};
  c.winding = PartLimits{120.0, 150.0, 30.0, 2.5, 0.5};
  c.freshness = Freshness{500'000, 50'000};
  return c;
}

TEST(SupervisorReadings, RawWhileValidWithConfiguredSigmaAndRpemdsAge) {
  rpem::estimate_t m = test::raw_estimate(kT0, 90.0, 80.0);
  m.r_s_age_s = 12.5;  // held
  const PartReadings r = readings_of(m, config());
  ASSERT_TRUE(r.magnet && r.winding);
  EXPECT_EQ(r.magnet->t_C, 90.0);
  EXPECT_EQ(r.magnet->sd_K, 4.0);
  EXPECT_EQ(r.magnet->unrenewed_s, 0.0);
  EXPECT_EQ(r.winding->sd_K, 2.5);
  EXPECT_EQ(r.winding->unrenewed_s, 12.5);
  m.psi_m_valid = false;  // never identified, or held beyond validity.max_hold_s
  m.t_winding_C = std::numeric_limits<double>::quiet_NaN();
  const PartReadings none = readings_of(m, config());
  EXPECT_FALSE(none.magnet);
  EXPECT_FALSE(none.winding);
  // Just identified and still moving towards the part's temperature (outside the convergence band): not yet one.
  m = test::raw_estimate(kT0, 90.0, 80.0);
  m.psi_m_converged = false;
  const PartReadings moving = readings_of(m, config());
  EXPECT_FALSE(moving.magnet);
  ASSERT_TRUE(moving.winding);
  EXPECT_EQ(moving.winding->t_C, 80.0);
}

TEST(SupervisorReadings, FusedWhenTheThermalModelRunsWhateverTheRawValuesSay) {
  rpem::estimate_t m = test::raw_estimate(kT0, 20.0, 20.0);
  m.psi_m_valid = false;
  m.thermal_active = true;
  m.t_magnet_fused_C = 105.0;
  m.t_magnet_fused_sd_C = 1.5;
  m.t_magnet_source = rpem::estimate_t::SOURCE_PREDICTED;
  m.t_winding_fused_C = 118.0;
  m.t_winding_fused_sd_C = 0.8;
  m.t_winding_source = rpem::estimate_t::SOURCE_NONE;
  const PartReadings r = readings_of(m, config());
  ASSERT_TRUE(r.magnet);
  EXPECT_EQ(r.magnet->t_C, 105.0);
  EXPECT_EQ(r.magnet->sd_K, 1.5);
  EXPECT_EQ(r.magnet->unrenewed_s, 0.0);
  EXPECT_FALSE(r.winding);
  m.t_magnet_fused_sd_C = -1.0;  // no standard deviation at all
  EXPECT_FALSE(readings_of(m, config()).magnet);
}

struct SupervisorTest : ::testing::Test {
  auth::Key key = test::test_key(2);
  Supervisor supervisor{config(), [] {
                          auth::Keyring k;
                          k.add(test::test_key(2));
                          return k;
                        }()};
  Admission send(const std::vector<std::uint8_t>& bytes, std::int64_t now_us) {
    return supervisor.on_message("RPEM_ESTIMATE", bytes, now_us).verdict;
  }
};

TEST_F(SupervisorTest, NothingTrustedYetGivesTheSmallerFloor) {
  const CurrentLimit l = supervisor.current_limit(kT0);
  EXPECT_FALSE(l.fresh);
  EXPECT_FALSE(l.magnet_upper_C);
  EXPECT_EQ(l.current_A, 30.0);
}

TEST_F(SupervisorTest, DeratesOnTheHotterPartAgedToTheMomentAsked) {
  rpem::estimate_t m = test::raw_estimate(kT0, 110.0, 100.0);
  m.r_s_age_s = 4.0;
  ASSERT_EQ(send(test::encode_signed(m, &key), kT0 + 10'000), Admission::kAccepted);
  // 0.2 s after utime. Magnet: T+ = 110 + 2·4 + 0.05·0.2 = 118.01 → 120 − 90·18.01/40 = 79.4775 A.
  // Winding: T+ = 100 + 2·2.5 + 0.5·(4 + 0.2) = 107.1 → below W = 120: 120 A.
  const CurrentLimit l = supervisor.current_limit(kT0 + 200'000);
  EXPECT_TRUE(l.fresh);
  ASSERT_TRUE(l.magnet_upper_C && l.winding_upper_C);
  EXPECT_NEAR(*l.magnet_upper_C, 118.01, 1e-9);
  EXPECT_NEAR(*l.winding_upper_C, 107.1, 1e-9);
  EXPECT_NEAR(l.magnet_A, 79.4775, 1e-9);
  EXPECT_EQ(l.winding_A, 120.0);
  EXPECT_NEAR(l.current_A, 79.4775, 1e-9);
  // Once the estimate is stale (0.55 s after utime) nothing is trusted: the floor.
  EXPECT_TRUE(supervisor.current_limit(kT0 + 550'000).fresh);
  const CurrentLimit stale = supervisor.current_limit(kT0 + 550'001);
  EXPECT_FALSE(stale.fresh);
  EXPECT_EQ(stale.current_A, 30.0);
}

TEST_F(SupervisorTest, ForgedOrReplayedColdMagnetsNeverLiftTheLimit) {
  const std::vector<std::uint8_t> cold = test::encode_signed(test::raw_estimate(kT0, 25.0, 25.0), &key);
  ASSERT_EQ(send(cold, kT0 + 1'000), Admission::kAccepted);
  EXPECT_EQ(supervisor.current_limit(kT0 + 2'000).current_A, 120.0);
  // Hot, then above the magnet's limit: nothing.
  ASSERT_EQ(send(test::encode_signed(test::raw_estimate(kT0 + 100'000, 135.0, 90.0), &key), kT0 + 101'000),
            Admission::kAccepted);
  const double hot_A = supervisor.current_limit(kT0 + 102'000).current_A;
  EXPECT_EQ(hot_A, 0.0);  // T+ = 143 > L = 140
  const auth::Key guessed = test::test_key(2, 1);
  EXPECT_EQ(send(test::encode_signed(test::raw_estimate(kT0 + 150'000, 25.0, 25.0), &guessed), kT0 + 151'000),
            Admission::kBadMac);
  EXPECT_EQ(send(test::encode_signed(test::raw_estimate(kT0 + 150'000, 25.0, 25.0), nullptr), kT0 + 151'000),
            Admission::kUnsigned);
  EXPECT_EQ(send(cold, kT0 + 152'000), Admission::kNotNewer);
  EXPECT_EQ(supervisor.current_limit(kT0 + 153'000).current_A, hot_A);
  EXPECT_EQ(send(cold, kT0 + 3'600'000'000), Admission::kStale);             // an hour later
  EXPECT_EQ(supervisor.current_limit(kT0 + 3'600'000'000).current_A, 30.0);  // the floor, not 120 A
}

TEST_F(SupervisorTest, AStaleRpemdsHeldEstimatesNeverLiftTheFloorAfterTheSilence) {
  // A new user's walk (2026-12-06): rpemd stale at 6 s, its estimates (state 2) repeating the last sample time at
  // 10 Hz; once the last running one aged out, the silence rule took the next stale one as a restart, and I_max
  // flipped between the floor and 120 A for as long as rpemd stayed stale.
  rpem::estimate_t running = test::raw_estimate(kT0, 45.0, 44.7);
  ASSERT_EQ(send(test::encode_signed(running, &key), kT0 + 1'000), Admission::kAccepted);
  for (int k = 1; k <= 30; ++k) {  // 3 s of held estimates
    rpem::estimate_t held = running;
    held.utime = kT0 + k * 100'000;
    held.state = rpem::estimate_t::STATE_STALE;
    ASSERT_EQ(send(test::encode_signed(held, &key), held.utime + 1'000), Admission::kNotRunning) << k;
    const CurrentLimit l = supervisor.current_limit(held.utime + 2'000);
    EXPECT_EQ(l.current_A, held.utime + 2'000 - kT0 <= 550'000 ? 120.0 : 30.0) << k;  // the floor once stale
  }
  // Starting (no sample yet: initial or resumed values) and stopping are held values too; running again, accepted.
  for (const std::int8_t state : {rpem::estimate_t::STATE_STARTING, rpem::estimate_t::STATE_STOPPING}) {
    rpem::estimate_t held = test::raw_estimate(kT0 + 3'100'000, 25.0, 25.0);
    held.state = state;
    EXPECT_EQ(send(test::encode_signed(held, &key), kT0 + 3'101'000), Admission::kNotRunning);
  }
  EXPECT_EQ(supervisor.current_limit(kT0 + 3'102'000).current_A, 30.0);
  ASSERT_EQ(send(test::encode_signed(test::raw_estimate(kT0 + 3'200'000, 45.0, 44.7), &key), kT0 + 3'201'000),
            Admission::kAccepted);
  EXPECT_EQ(supervisor.current_limit(kT0 + 3'202'000).current_A, 120.0);
}

TEST(SupervisorConfig, TheExampleFileLoads) {
  const Config c = load_config(std::string(RPEM_TEST_SOURCE_DIR) + "/examples/supervisor/supervisor.yaml");
  const Config e = config();
  EXPECT_EQ(c.rated_current_A, e.rated_current_A);
  for (const auto& [got, want] : {std::pair{c.magnet, e.magnet}, std::pair{c.winding, e.winding}}) {
    EXPECT_EQ(got.warning_C, want.warning_C);
    EXPECT_EQ(got.limit_C, want.limit_C);
    EXPECT_EQ(got.floor_A, want.floor_A);
    EXPECT_EQ(got.raw_sd_K, want.raw_sd_K);
    EXPECT_EQ(got.max_rate_K_s, want.max_rate_K_s);
  }
  EXPECT_EQ(c.freshness.max_age_us, 500'000);
  EXPECT_EQ(c.freshness.max_skew_us, 50'000);
}

TEST(SupervisorConfig, BadFilesAreRefusedNamingLineAndKey) {
  const std::string part = "{warning_C: 100, limit_C: 140, floor_A: 30, raw_sd_K: 4, max_rate_K_s: 0.05}";
  const auto refused = [&](const std::string& text) -> std::string {
    test::TempFile f("supervisor.yaml", text);
    try {
      (void)load_config(f.path());
    } catch (const io::ConfigError& e) {
      return e.what();
    }
    return "accepted";
  };
  const std::string good_tail = "  winding: " + part + "\n  freshness: {max_age_s: 0.5, max_skew_s: 0.05}\n";
  EXPECT_NE(
      refused(
          "supervisor:\n  rated_current_A: 120\n  magnet: {warning_C: 100, limit_C: 90, floor_A: 30, raw_sd_K: 4, max_rate_K_s: 0.05}\n" +
          good_tail)
          .find(":3:"),
      std::string::npos);
  EXPECT_NE(
      refused(
          "supervisor:\n  rated_current_A: 120\n  magnet: {warning_C: 100, limit_C: 140, floor_A: 130, raw_sd_K: 4, max_rate_K_s: 0.05}\n" +
          good_tail)
          .find("floor_A"),
      std::string::npos);
  EXPECT_NE(refused("supervisor:\n  rated_current_A: 120\n  magnet: " + part + "\n  manget: " + part + "\n" + good_tail)
                .find("manget"),
            std::string::npos);
  EXPECT_NE(refused("supervisor:\n  rated_current_A: 120\n" + good_tail).find("magnet"), std::string::npos);
}

}  // namespace
}  // namespace rpem::supervisor
