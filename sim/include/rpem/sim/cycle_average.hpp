#pragma once
// Averaged rotor-frame samples from the simulated drive, as a drive that averages every control cycle
// reports them (VESC's avg_id/avg_iq/avg_vd/avg_vq, docs/can-vesc.md): `rpem sim --averaged-out`,
// `rpem sim --vesc` and the averaged-mode tests.
//
// Cycle k covers [t_k, t_k+1]. Its current is the measured current at t_k in the rotor frame at the
// measured angle ϑ_k (what a drive samples); its voltage is the rotor-frame mean of the command held in the
// stator frame over the cycle, at the measured angles,
//   ū_k = sinc(Δϑ/2)·T(ϑ_k + Δϑ/2)·u^s_k,   Δϑ = ϑ_k+1 − ϑ_k
// (a drive with exact phase compensation, as VESC's advance of the angle by ω·dt/2 intends); speed, DC link
// and temperatures as measured at t_k. A window's temperature is the mean of the readings its cycles have (a slow
// sensor reads on few of them: the native protocol's temperature frame comes every 100 ms), NaN with none.

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>

#include "rpem/core/averaged_sample.hpp"
#include "rpem/io/drive_log.hpp"

namespace rpem::sim {

struct ControlCycle {
  std::int64_t t_ns = 0;    ///< start of the cycle
  std::int64_t end_ns = 0;  ///< start of the next one
  core::Vec2 i_dq_A = core::Vec2::Zero();
  core::Vec2 u_dq_V = core::Vec2::Zero();
  double omega_el_rad_s = 0.0;
  double theta_el_rad = 0.0;  ///< the measured angle at the cycle's start (the frame of i_dq_A)
  double u_dc_V = 0.0;
  double t_winding_C = 0.0, t_magnet_C = 0.0, t_coolant_C = 0.0;
};

/// Turns consecutive drive-log rows into control cycles: cycle k is complete when row k+1 arrives.
class CycleExtractor {
 public:
  [[nodiscard]] std::optional<ControlCycle> add(const io::DriveLogRow& row) noexcept;

 private:
  std::optional<io::DriveLogRow> previous_;
};

/// The mean of the readings added since the last read, NaN without one (a NaN added is no reading).
class ReadingMean {
 public:
  void add(double v) noexcept {
    if (std::isnan(v)) return;
    sum_ += v;
    ++n_;
  }
  [[nodiscard]] double mean() const noexcept { return n_ > 0 ? sum_ / n_ : std::numeric_limits<double>::quiet_NaN(); }

 private:
  double sum_ = 0.0;
  int n_ = 0;
};

/// Means of control cycles since the last read (no allocation).
class CycleAccumulator {
 public:
  void add(const ControlCycle& c) noexcept;
  [[nodiscard]] int cycles() const noexcept { return n_; }
  /// The means over the cycles since the previous read, as the window [start of the first, end of the last].
  [[nodiscard]] core::AveragedSample read_reset() noexcept;

 private:
  int n_ = 0;
  std::int64_t first_ns_ = 0, last_end_ns_ = 0;
  core::Vec2 i_ = core::Vec2::Zero(), u_ = core::Vec2::Zero();
  double omega_ = 0.0, u_dc_ = 0.0;
  ReadingMean t_winding_, t_magnet_, t_coolant_;
};

/// Windows of uneven length — uniform in (1 ± jitter)/rate, clipped to [0.5, 20] ms — closing at the first
/// cycle boundary at or after their scheduled end.
class WindowAverager {
 public:
  WindowAverager(double rate_Hz, double jitter, std::uint64_t seed);
  /// Adds a cycle; returns the window it closes, if any.
  [[nodiscard]] std::optional<core::AveragedSample> add(const ControlCycle& c);

 private:
  [[nodiscard]] std::int64_t draw_length_ns();

  double rate_Hz_, jitter_;
  std::mt19937_64 rng_;
  CycleAccumulator sums_;
  std::int64_t window_end_ns_ = 0;
  bool started_ = false;
};

}  // namespace rpem::sim
