#pragma once
// Whether the windows R_s adapted on agree on one resistance (docs/drive-log.md, "A voltage along the current";
// docs/derivations.md §12, eq. 12.1). At each such window k the estimator's model leaves the voltage
// y_k = r̂_{k−1}·(î_k·i_k)/|i_k| to the drop along the current (î = e/r̂ with the speed terms taken out). A voltage
// the model leaves out along the current (an inverter's dead time the drive compensates in part; a sensorless
// stall's rocking, whose back EMF falls along the current: docs/drive-log.md, "What the stall is") makes it
// y = R·|i| + V: the estimator, which takes V = 0, reads R + V/|i|, and every start it is run
// from agrees on that, so the identifiability runs cannot see it. Fitted by least squares over the windows,
//   y_k = R·|i_k| + V + R₁·(t_k − t̄)·|i_k|                                                         (12.1)
// (R₁: the winding's drift over the log, to first order), R at the last window is the resistance the log implies
// with V taken out. Not real-time code: run once after the log.

#include <cstddef>
#include <optional>
#include <vector>

namespace rpem::analysis {

/// One window where R_s adapted.
struct RsReading {
  double t_s = 0.0;
  double current_A = 0.0;  ///< |i|
  double voltage_V = 0.0;  ///< y: what the model leaves to the drop along the current
};

/// The fit of (12.1) over the readings.
struct RsAlongCurrent {
  std::size_t readings = 0;
  double r_at_last_Ohm = 0.0, r_at_last_se_Ohm = 0.0;  ///< R + R₁·(t_last − t̄) and its standard error
  double v_V = 0.0, v_se_V = 0.0;                      ///< the voltage the model leaves out
  double current_min_A = 0.0, current_max_A = 0.0;
};

/// (12.1) by least squares; empty with fewer than six readings (three parameters and three degrees of freedom
/// for the residual's variance) or where the readings cannot tell R from V and the drift (one current, one time).
[[nodiscard]] std::optional<RsAlongCurrent> fit_rs_along_current(const std::vector<RsReading>& readings);

}  // namespace rpem::analysis
