#pragma once
// Switching-level simulation from one switching instant to the next (docs/derivations.md §10,
// docs/scenarios.md `plant.integrator: edges`). Over a half carrier period each leg's gates switch at
// most once, at its PWM edge and a dead time later (Inverter::schedule); between these instants every
// leg holds one voltage as long as its phase current keeps its sign, so the plant is integrated over
// each interval in one piece — exactly for constant inductances (LinearFlow), under error control for
// a flux map (MapFlow).
//
// A phase current's sign matters where the leg voltage depends on it: during blanking (the diode the
// current selects sets the leg) and, with device drops, always. There the search for its zero
// crossings — on the sign change over the interval, or on a turning point of the current towards zero
// inside it — finds the first one by safeguarded Newton iteration on the interval's exact (or
// interpolated) trajectory, and the integration restarts there. A current that reaches zero stays
// there if neither sign's voltage drives it away (zero-current clamping: during blanking both diodes
// block): the clamped phase then takes the voltage in between that keeps its current at zero, solved
// over sub-intervals of at most kClampStep_s (exactly, for constant inductances, since the end current
// is affine in the leg voltage), until a sign's voltage drives the current off zero again.

#include <array>
#include <cstdint>

#include "rpem/sim/inverter.hpp"
#include "rpem/sim/linear_flow.hpp"
#include "rpem/sim/map_flow.hpp"
#include "rpem/sim/plant.hpp"

namespace rpem::sim {

/// What the edge-to-edge integration did, for tests and profiles.
struct EdgeCounters {
  std::int64_t half_periods = 0;
  std::int64_t intervals = 0;       ///< pieces integrated in one go
  std::int64_t zero_crossings = 0;  ///< located by root finding
  std::int64_t clamped_intervals = 0;
  std::int64_t event_limit_hits = 0;  ///< half periods that reached kMaxEvents (see below)
};

class EdgeIntegrator {
 public:
  /// Sub-interval over which a clamped phase's voltage is held constant.
  static constexpr double kClampStep_s = 5e-6;
  /// Zero crossings handled per half period; beyond, signs keep their values to the period's end
  /// (a safeguard against chattering, counted in EdgeCounters::event_limit_hits).
  static constexpr int kMaxEvents = 48;
  /// A phase current this small keeps the sign (or the clamp) the last zero crossing decided.
  static constexpr double kZeroCurrent_A = 1e-7;

  /// `tolerance`: MapFlow's relative local error per step (flux maps only).
  EdgeIntegrator(const InverterConfig& inverter, double tolerance) noexcept;

  /// Integrates the plant over one half carrier period (rising: from valley to peak) with the legs'
  /// duties on the true DC link u_dc_V. The plant's period must have begun with
  /// begin_period(parameters, half period, load).
  void integrate(PmsmPlant& plant, bool rising, const Duties& duties, double u_dc_V) noexcept;

  [[nodiscard]] const EdgeCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const MapFlow& map_flow() const noexcept { return map_; }

 private:
  /// The voltages each leg takes over an interval: for a positive current, a negative one, and the
  /// one applied.
  struct Legs {
    core::Vec3 positive_V = core::Vec3::Zero();
    core::Vec3 negative_V = core::Vec3::Zero();
    core::Vec3 applied_V = core::Vec3::Zero();
  };

  template <class Flow>
  void run(Flow& flow, PmsmPlant& plant, bool rising, const Duties& duties, double u_dc_V) noexcept;
  /// Starts the interval with phase x at zero current: its sign if one of its voltages drives the
  /// current off zero over h_s, else the clamp voltage that keeps it at zero.
  template <class Flow>
  void start_at_zero(Flow& flow, const PmsmPlant& plant, int x, Legs& legs, double h_s) noexcept;
  /// Each leg's command over an interval (at its midpoint t_mid) and each current's sign where it is clearly
  /// off zero, one phase clamped at a time: the legs' voltages in `legs`; the clamped phase, or -1.
  int select_legs(const std::array<LegSchedule, 3>& schedule, const core::Vec3& i, double t_mid, double u_dc_V,
                  Legs& legs) noexcept;
  /// The first zero crossing among the watched phases within [0, h_s]: its phase, its instant in
  /// t_cross_s (which comes in as h_s); -1 (t_cross_s unchanged) if none.
  template <class Flow>
  int first_watched_crossing(const Flow& flow, const std::array<bool, 3>& watched, double h_s,
                             double& t_cross_s) const noexcept;
  /// The first zero crossing of phase x (of sign `sign_[x]` at the start) within [0, h_s]; < 0: none.
  template <class Flow>
  [[nodiscard]] double first_crossing(const Flow& flow, int x, const PhaseCurrents& begin, const PhaseCurrents& end,
                                      double h_s) const noexcept;

  Inverter inverter_;
  LinearFlow linear_;
  MapFlow map_;
  bool signs_matter_;                 ///< dead time or device drops: the currents' signs select leg voltages
  std::array<int, 3> sign_{1, 1, 1};  ///< each phase current's sign: +1, −1, or 0 (clamped at zero)
  EdgeCounters counters_;
};

}  // namespace rpem::sim
