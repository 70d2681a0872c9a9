#pragma once
// The plant as one ODE (README.md, "Plant"): the three node temperatures, the winding sensor's lag, the
// coolant (a boundary of the network; constant or a loop with its own heat balance), four energy
// accumulators (losses per node, heat into the coolant) integrated with the same stages, so that
//   Σ C_i·(T_i(t) − T_i(0)) = E_winding + E_iron + E_rotor − E_coolant
// is an invariant of the discrete solution (Runge-Kutta methods keep linear invariants), and the time
// integrals of the logged electrical quantities (for window means: the averaged log).
#include <Eigen/Dense>

#include "indep_thermal/electrical.hpp"
#include "indep_thermal/losses.hpp"
#include "indep_thermal/machine.hpp"
#include "indep_thermal/network.hpp"
#include "indep_thermal/parameters.hpp"
#include "indep_thermal/profile.hpp"

namespace indep_thermal {

enum class CoolantMode { constant, loop };

/// State layout.
enum StateIndex : int {
  kTWinding = 0,
  kTIron = 1,
  kTRotor = 2,
  kTSensorLag = 3,  // the winding sensor's element, first-order lag of T_winding
  kTCoolant = 4,
  kEWinding = 5,  // ∫ losses into each node [J]
  kEIron = 6,
  kERotor = 7,
  kECoolant = 8,    // ∫ heat into the coolant [J]
  kIdIntegral = 9,  // ∫ i_d dt, ∫ i_q dt [A·s], ∫ u_d dt, ∫ u_q dt [V·s], ∫ ω_el dt [rad]
  kIqIntegral = 10,
  kUdIntegral = 11,
  kUqIntegral = 12,
  kOmegaIntegral = 13,
  kStateSize = 14,
  kTemperatureStates = 5,  // the states the step control watches
};

using State = Eigen::Matrix<double, kStateSize, 1>;

/// Everything at one instant.
struct Snapshot {
  double t_s = 0.0;
  Demand demand;
  OperatingPoint op;
  double speed_rpm = 0.0;
  Losses losses;
  Conductances g;
  DqVoltage u;
  double r_s_dc_Ohm = 0.0;
  double r_s_ac_Ohm = 0.0;
  double psi_m_Wb = 0.0;
  double sensor_reading_C = 0.0;  // T_c + gain·(T_lag − T_c), before noise
  double heat_to_coolant_W = 0.0;
  double other_heat_W = 0.0;  // loop mode
  State y;
  State dydt;
};

class Plant {
 public:
  Plant(const Machine& configured, const Parameters& p, const Profile& profile, CoolantMode mode);

  [[nodiscard]] State initial_state() const;
  /// dy/dt at (t, y); `left_limit`: with the profile's demand from before t (profile.hpp).
  [[nodiscard]] State derivative(double t, const State& y, bool left_limit = false) const {
    return evaluate(t, y, left_limit).dydt;
  }
  [[nodiscard]] Snapshot evaluate(double t, const State& y, bool left_limit = false) const;
  /// Σ C_i·(T_i − T_i(0)) [J].
  [[nodiscard]] double stored_heat_J(const State& y) const;

  [[nodiscard]] const Parameters& parameters() const { return p_; }
  [[nodiscard]] const Profile& profile() const { return profile_; }
  [[nodiscard]] CoolantMode coolant_mode() const { return mode_; }

 private:
  Machine configured_;
  Parameters p_;
  Profile profile_;
  CoolantMode mode_;
  Eigen::Vector3d c_;
  State y0_;
};

}  // namespace indep_thermal
