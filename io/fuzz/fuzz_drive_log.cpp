// libFuzzer target for the drive-log CSV reader (docs/drive-log.md): the input is the file's bytes. The
// reader must never crash and may fail only with DriveLogError; every row it delivers must be finite,
// within DriveLogLimits, later than the row before, and in the frames its layout promises; and the
// estimator (the built-in paper machine) must keep its estimates finite and inside D_M on those rows.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "rpem/core/drive_estimator.hpp"
#include "rpem/io/drive_log.hpp"
#include "rpem/io/machine_config.hpp"

namespace {

void check(bool ok) {
  if (!ok) std::abort();
}

bool within(double v, const rpem::io::Bound& b) { return std::isfinite(v) && std::abs(v) <= b.max_abs; }

/// Inside D_M to rounding: the estimator projects in pu, and the SI value carries the conversion's rounding.
bool inside(double v, double lo, double hi) {
  return std::isfinite(v) && v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rpem;
  static const io::MachineConfig config = io::builtin_paper_config();
  const io::DriveLogLimits limits;
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  static core::DriveEstimator estimator(config.machine, config.estimator);
  estimator.reset();
  const core::EstimatorSettings& s = config.estimator;
  try {
    io::DriveLogReader reader(in, "fuzz.csv", limits);
    const io::DriveLogLayout& layout = reader.layout();
    io::DriveLogRow row;
    std::int64_t last_t_ns = INT64_MIN;
    while (reader.next(row)) {
      const core::DriveSample& x = row.sample;
      check(x.t_ns > last_t_ns);
      last_t_ns = x.t_ns;
      check(within(x.theta_el_rad, limits.angle_rad) && within(x.omega_el_rad_s, limits.speed_rad_s) &&
            within(x.u_dc_V, limits.voltage_V));
      check(x.voltage_frame == (layout.voltage_abc ? core::Frame::kAbc : core::Frame::kDq));
      check(x.current_frame == (layout.current_abc ? core::Frame::kAbc : core::Frame::kDq));
      for (int k = 0; k < 3; ++k) check(within(x.u_V[k], limits.voltage_V) && within(x.i_A[k], limits.current_A));
      check(!row.t_magnet_C || (*row.t_magnet_C >= limits.temperature_min_C && *row.t_magnet_C <= limits.temperature_max_C));
      const core::Estimate e = estimator.step(x);
      check(inside(e.psi_m_Wb, s.psi_m_min_Wb, s.psi_m_max_Wb) && inside(e.r_s_Ohm, s.r_s_min_Ohm, s.r_s_max_Ohm));
    }
    check(reader.line() >= 2);  // a log without samples must have thrown
  } catch (const io::DriveLogError&) {
  }
  return 0;
}
