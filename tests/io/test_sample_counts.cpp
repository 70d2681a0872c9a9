// io::SampleCounts (its core::RegimeCounts): the samples that excited R_s only because a position sensor's frame was
// assumed (the configuration does not say estimator.regimes.angle_source) are counted where they adapted, and the
// tools' note says how many of all that excited R_s; a resync is a chain started over, not its start.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/regime.hpp"
#include "rpem/io/sample_counts.hpp"

namespace rpem::io {
namespace {

core::Estimate estimate(std::uint8_t bits, core::StepCode code = core::StepCode::kAdapted) {
  core::Estimate e;
  e.regime = core::Classification::of(bits);
  e.detail.code = code;
  return e;
}

// Before, a clean log's summary said "1 resyncs": its first sample's synchronisation.
TEST(SampleCounts, AResyncIsAChainStartedOverNotTheStartOfOne) {
  using core::StepCode;
  SampleCounts c;
  c.add(estimate(0, StepCode::kSynchronized));  // the estimator's first sample
  c.add(estimate(0));
  EXPECT_EQ(c.resyncs, 0U);
  c.add(estimate(0, StepCode::kSynchronized));  // a gap
  c.add(estimate(0, StepCode::kPredictorDiverged));
  EXPECT_EQ(c.resyncs, 2U);
  c.start_session();                            // the estimator reset for a session
  c.add(estimate(0, StepCode::kSynchronized));  // its first sample
  EXPECT_EQ(c.resyncs, 2U);
  c.add(estimate(0, StepCode::kSynchronized));
  EXPECT_EQ(c.resyncs, 3U);
  EXPECT_EQ(c.samples, 6U);
}

TEST(SampleCounts, WhatExcitedRsOnlyOnAnAssumedFrameIsCountedWhereItAdapted) {
  using namespace core::regime_bit;
  SampleCounts c;
  EXPECT_EQ(assumed_frame_note(c), "");
  c.add(estimate(kExcitesRs));                                   // on any frame
  c.add(estimate(kExcitesRs | kRsOnAssumedFrame));               // only on the assumed one
  c.add(estimate(kTransient | kExcitesRs | kRsOnAssumedFrame));  // excluded: adapted nothing
  EXPECT_EQ(c.regimes.r_s_on_assumed_frame, 1U);
  c.add(estimate(kExcitesPsiM | kExcitesRs | kRsOnAssumedFrame));
  EXPECT_EQ(c.regimes.r_s_on_assumed_frame, 2U);
  EXPECT_EQ(assumed_frame_note(c).rfind("2 of the 3 samples that excited R_s did so only because the drive's dq frame "
                                        "was taken as a position sensor's",
                                        0),
            0U)
      << assumed_frame_note(c);
  // The next window shows the last one mixed (the bridge released inside it): it moves to transient and is taken
  // back, as RegimeCounts moves it.
  c.add(estimate(kBridgeOff | kPreviousMixed));
  EXPECT_EQ(c.regimes.r_s_on_assumed_frame, 1U);
  EXPECT_EQ(c.regimes[core::Regime::kExcitesBoth], 0U);
  EXPECT_NE(assumed_frame_note(c).find("1 of the 2 samples"), std::string::npos) << assumed_frame_note(c);
  EXPECT_NE(assumed_frame_note(c).find("say angle_source: sensorless"), std::string::npos);
  // A mixed window after one that did not rest on the frame takes nothing back.
  c.add(estimate(kExcitesRs));
  c.add(estimate(kBridgeOff | kPreviousMixed));
  EXPECT_EQ(c.regimes.r_s_on_assumed_frame, 1U);
}

}  // namespace
}  // namespace rpem::io
