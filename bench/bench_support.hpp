#pragma once
// What the estimator's and the thermal fusion's benchmarks share: the paper machine's phase samples from the
// model (tests/support/model_data.hpp; the plant's ψm 5 % below the configuration's, n = 0.4 pu on the MTPA
// current, 0.2 % current noise), this thread's CPU clock, and the repetitions' maximum statistic.

#include <algorithm>
#include <cstdint>
#include <ctime>
#include <vector>

#include "rpem/core/clock.hpp"
#include "rpem/core/drive_sample.hpp"
#include "support/model_data.hpp"
#include "support/paper_machine.hpp"

namespace rpem::bench {

/// `count` consecutive samples at the model's rate, from t = 0.
inline std::vector<core::DriveSample> paper_drive_samples(int count) {
  const core::PerUnitBase base = test::paper_base();
  test::ModelDataGenerator gen;
  gen.plant = test::paper_machine_pu();
  gen.plant.psi_m_pu *= 0.95;
  gen.omega_n_rad_s = base.omega_el_rad_s;
  gen.n_pu = 0.4;
  gen.i_ref_pu = core::mtpa_reference(gen.plant, 0.4);
  gen.current_noise_pu = 0.002;
  std::vector<core::DriveSample> v;
  v.reserve(static_cast<std::size_t>(count));
  std::int64_t t_ns = 0;
  for (int k = 0; k < count; ++k) v.push_back(gen.next_si(base, t_ns));
  return v;
}

/// This thread's CPU time: what a block of steps cost, whatever else the host runs.
inline double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + core::to_seconds(ts.tv_nsec);
}

/// The repetitions' maximum (ComputeStatistics("max", …)).
inline double max_of(const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); }

}  // namespace rpem::bench
