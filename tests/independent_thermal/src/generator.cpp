#include "indep_thermal/generator.hpp"

#include <cmath>

#include "indep_thermal/errors.hpp"
#include "indep_thermal/random.hpp"

namespace indep_thermal {

namespace {

// x rounded to a multiple of the quantum; a quantum 1/k (k whole: 0.1, 0.01) divides by k, so that the result
// is the double nearest the decimal (17.9, not 17.900000000000002).
double quantise(double x, double quantum) {
  if (!(quantum > 0.0)) return x;
  const double n = std::round(x / quantum);
  const double per_unit = std::round(1.0 / quantum);
  return std::abs(per_unit * quantum - 1.0) < 1e-12 ? n / per_unit : n * quantum;
}

}  // namespace

Profile make_profile(const std::string& name, const Machine& machine, double duration_s, std::uint64_t seed,
                     double load_scale) {
  if (!(load_scale > 0.0 && load_scale <= 3.0)) throw UsageError("load scale must be in (0, 3]");
  if (name == "drive-cycle") return drive_cycle_profile(machine, duration_s, seed, load_scale);
  if (name == "heat-cool") return heat_cool_profile(machine, duration_s);
  return read_profile_csv(name);
}

Result generate(const Case& c, const RowSink& sink) {
  if (!(c.duration_s > 0.0) || !std::isfinite(c.duration_s)) throw UsageError("duration must be > 0 s");
  if (!(c.rate_Hz > 0.0) || !std::isfinite(c.rate_Hz)) throw UsageError("row rate must be > 0 Hz");
  if (c.duration_s * c.rate_Hz > 1e8) throw UsageError("more than 1e8 rows: lower the duration or the rate");
  const Plant plant(c.machine, c.params, c.profile, c.coolant);
  DormandPrince<kStateSize> solver(c.control);
  const Parameters& p = plant.parameters();
  Rng noise(c.seed, Stream::noise);
  const double sigma_i = c.noise ? p.noise_current_rel * p.rated_current_A : 0.0;
  const double sigma_u = c.noise ? p.noise_voltage_rel * c.machine.peak_voltage_V() : 0.0;

  const std::vector<double> knots = c.profile.knots();
  std::size_t next_knot = 0;
  const auto rows = static_cast<std::size_t>(std::floor(c.duration_s * c.rate_Hz + 1e-9)) + 1;
  Result r;
  if (c.keep_rows) r.rows.reserve(rows);
  Summary& sum = r.summary;
  State y = plant.initial_state();
  State y_previous_row = y;
  double t = 0.0;
  double t_previous_row = 0.0;
  double segment_end = 0.0;
  // Within [t, segment_end] the demand is smooth; a stage at segment_end takes its limit from before.
  const auto f = [&](double tt, const State& yy) { return plant.derivative(tt, yy, tt >= segment_end); };
  for (std::size_t k = 0; k < rows; ++k) {
    const double t_row = static_cast<double>(k) / c.rate_Hz;
    while (next_knot < knots.size() && knots[next_knot] <= t) ++next_knot;
    while (next_knot < knots.size() && knots[next_knot] < t_row) {
      segment_end = knots[next_knot++];
      solver.advance(f, t, segment_end, y);
    }
    segment_end = t_row;
    solver.advance(f, t, t_row, y);

    Row row;
    row.truth = plant.evaluate(t_row, y);
    const Snapshot& s = row.truth;
    row.t_start_s = t_previous_row;
    row.stored_J = plant.stored_heat_J(y);
    row.residual_J = row.stored_J - (y(kEWinding) + y(kEIron) + y(kERotor) - y(kECoolant));
    if (k == 0) {
      row.i_d_mean_A = s.op.i_d_A;
      row.i_q_mean_A = s.op.i_q_A;
      row.u_d_mean_V = s.u.u_d_V;
      row.u_q_mean_V = s.u.u_q_V;
      row.omega_el_mean_rad_s = s.op.omega_el_rad_s;
    } else {
      const double width = t_row - t_previous_row;
      const State mean = (y - y_previous_row) / width;
      row.i_d_mean_A = mean(kIdIntegral);
      row.i_q_mean_A = mean(kIqIntegral);
      row.u_d_mean_V = mean(kUdIntegral);
      row.u_q_mean_V = mean(kUqIntegral);
      row.omega_el_mean_rad_s = mean(kOmegaIntegral);
    }
    // Six variates per row, drawn whether or not a column is written: the numbers do not depend on the flags.
    const double n_id = noise.normal(), n_iq = noise.normal(), n_ud = noise.normal(), n_uq = noise.normal();
    const double n_tw = noise.normal(), n_tc = noise.normal();
    row.i_d_A = (c.averaged ? row.i_d_mean_A : s.op.i_d_A) + sigma_i * n_id;
    row.i_q_A = (c.averaged ? row.i_q_mean_A : s.op.i_q_A) + sigma_i * n_iq;
    row.u_d_V = (c.averaged ? row.u_d_mean_V : s.u.u_d_V) + sigma_u * n_ud;
    row.u_q_V = (c.averaged ? row.u_q_mean_V : s.u.u_q_V) + sigma_u * n_uq;
    row.omega_el_rad_s = c.averaged ? row.omega_el_mean_rad_s : s.op.omega_el_rad_s;
    if (c.noise) {
      row.t_winding_C = quantise(s.sensor_reading_C + p.sensor_winding_noise_K * n_tw, p.sensor_winding_resolution_K);
      row.t_coolant_C = quantise(y(kTCoolant) + p.sensor_coolant_noise_K * n_tc, p.sensor_coolant_resolution_K);
    } else {
      row.t_winding_C = s.sensor_reading_C;
      row.t_coolant_C = y(kTCoolant);
    }

    sum.rows = k + 1;
    sum.t_winding_max_C = std::max(sum.t_winding_max_C, y(kTWinding));
    sum.t_iron_max_C = std::max(sum.t_iron_max_C, y(kTIron));
    sum.t_magnet_max_C = std::max(sum.t_magnet_max_C, y(kTRotor));
    sum.t_coolant_min_C = std::min(sum.t_coolant_min_C, y(kTCoolant));
    sum.t_coolant_max_C = std::max(sum.t_coolant_max_C, y(kTCoolant));
    sum.e_losses_J = y(kEWinding) + y(kEIron) + y(kERotor);
    sum.e_coolant_J = y(kECoolant);
    sum.max_abs_residual_J = std::max(sum.max_abs_residual_J, std::abs(row.residual_J));
    if (sink) sink(row);
    if (c.keep_rows) r.rows.push_back(std::move(row));
    y_previous_row = y;
    t_previous_row = t_row;
  }
  r.stats = solver.stats();
  return r;
}

}  // namespace indep_thermal
