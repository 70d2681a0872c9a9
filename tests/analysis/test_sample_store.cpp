// SampleStore's temperature columns (analysis/include/rpem/analysis/diagnose/sample_store.hpp): the reading on
// a row, and the temperature at a row the diagnosis's models take — the session's newest reading held, its
// first for the rows before it — across chunks and sessions.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <vector>

#include "rpem/analysis/diagnose/sample_store.hpp"

namespace rpem::analysis {
namespace {

const double kNone = std::nan("");

io::DriveLogRow row_at(std::size_t k, double winding_C, std::optional<double> magnet_C) {
  io::DriveLogRow r;
  r.sample.t_ns = static_cast<std::int64_t>(k) * 1000;
  r.sample.t_winding_C = winding_C;
  r.t_magnet_C = magnet_C;
  return r;
}

io::DriveLogLayout with_temperatures() {
  io::DriveLogLayout layout;
  layout.t_winding = true;
  layout.t_magnet = true;
  return layout;
}

TEST(SampleStore, ASlowSensorsReadingIsHeldUntilTheNextAndItsFirstStandsForTheRowsBefore) {
  // Readings every 10 000 rows from row 7 000 on (a chunk is 16 384 rows): 40.25, 41.5, 43.0 (exact floats) and
  // one that is not (42.1); the magnet column has a reading on row 0 only.
  SampleStore s(with_temperatures());
  const std::size_t n = 45'000;
  auto reading_of = [](std::size_t k) -> double {
    if (k < 7'000 || (k - 7'000) % 10'000 != 0) return kNone;
    const double r[] = {40.25, 41.5, 42.1, 43.0};
    return r[(k - 7'000) / 10'000];
  };
  for (std::size_t k = 0; k < n; ++k) s.push_back(row_at(k, reading_of(k), k == 0 ? std::optional(80.0) : kNone));
  s.finish();

  EXPECT_EQ(s.t_winding_C(6'999), std::nullopt);
  EXPECT_EQ(s.t_winding_C(7'000), 40.25);
  EXPECT_EQ(s.t_winding_C(7'001), std::nullopt);
  EXPECT_EQ(s.t_winding_C(27'000), 42.1);  // stored exactly where it is not a float
  // Held: the first reading for the rows before it, then each until the next, across chunk boundaries.
  EXPECT_EQ(s.t_winding_held_C(0), 40.25);
  EXPECT_EQ(s.t_winding_held_C(6'999), 40.25);
  EXPECT_EQ(s.t_winding_held_C(16'999), 40.25);
  EXPECT_EQ(s.t_winding_held_C(17'000), 41.5);
  EXPECT_EQ(s.t_winding_held_C(SampleStore::kChunk), 40.25);  // held from the chunk before
  EXPECT_EQ(s.t_winding_held_C(36'999), 42.1);
  EXPECT_EQ(s.t_winding_held_C(n - 1), 43.0);
  EXPECT_EQ(s.t_magnet_C(0), 80.0);
  EXPECT_EQ(s.t_magnet_C(1), std::nullopt);
  EXPECT_EQ(s.t_magnet_held_C(n - 1), 80.0);
}

TEST(SampleStore, NoReadingIsHeldIntoTheNextSession) {
  // Session 1 reads 30 °C on its row 2; session 2 (from row 10) reads nothing until its row 14 (55 °C);
  // session 3 (from row 20) reads nothing at all.
  SampleStore s(with_temperatures());
  for (std::size_t k = 0; k < 30; ++k) {
    if (k == 10 || k == 20) s.start_session();
    s.push_back(row_at(k, k == 2 ? 30.0 : k == 14 ? 55.0 : kNone, std::nullopt));
  }
  s.finish();
  for (std::size_t k = 0; k < 10; ++k) EXPECT_EQ(s.t_winding_held_C(k), 30.0) << k;
  for (std::size_t k = 10; k < 20; ++k) EXPECT_EQ(s.t_winding_held_C(k), 55.0) << k;
  for (std::size_t k = 20; k < 30; ++k) EXPECT_EQ(s.t_winding_held_C(k), std::nullopt) << k;
  for (std::size_t k = 0; k < 30; ++k) EXPECT_EQ(s.t_magnet_held_C(k), std::nullopt) << k;
}

TEST(SampleStore, AColumnTheLogLacksHasNoReadingAnywhere) {
  SampleStore s{io::DriveLogLayout{}};
  for (std::size_t k = 0; k < 3; ++k) s.push_back(row_at(k, 20.0, 20.0));
  s.finish();
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(s.t_winding_C(k), std::nullopt);
    EXPECT_EQ(s.t_winding_held_C(k), std::nullopt);
    EXPECT_EQ(s.t_magnet_held_C(k), std::nullopt);
  }
}

TEST(SampleStore, MarksOtherThanTheReadingsLeaveThemAlone) {
  SampleStore s(with_temperatures());
  s.push_back(row_at(0, 25.0, std::nullopt));
  s.push_back(row_at(1, kNone, std::nullopt));
  s.finish();
  s.set_mark(0, sample_mark::kLeftOut, true);
  s.set_mark(0, sample_mark::kLeftOut, false);
  EXPECT_EQ(s.t_winding_C(0), 25.0);
  EXPECT_EQ(s.t_winding_C(1), std::nullopt);
  EXPECT_EQ(s.t_winding_held_C(1), 25.0);
}

}  // namespace
}  // namespace rpem::analysis
