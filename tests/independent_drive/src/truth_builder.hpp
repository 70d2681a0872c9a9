#pragma once
// Builds the truth of a finished run (internal to the generator).
#include "indep_drive/case.hpp"
#include "indep_drive/flux_map.hpp"
#include "indep_drive/frames.hpp"
#include "indep_drive/truth.hpp"

namespace indep::detail {

/// The largest true currents met at the samples (magnetising current, rotor frame).
struct CurrentExtremes {
  Vec2 at_max_abs_d;
  Vec2 at_max_abs_q;
  Vec2 at_max_norm;
  void update(Vec2 i);
};

struct RunFacts {
  MachineParams true_machine;
  double initial_theta_rad = 0;
  CurrentExtremes extremes;
  const FluxMapFit* fit = nullptr;  // when a saturation effect is on
};

Truth build_truth(const Case& resolved, const RunFacts& facts);

}  // namespace indep::detail
