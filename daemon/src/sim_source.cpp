#include "rpem/daemon/sim_source.hpp"

#include <filesystem>

#include "rpem/core/clock.hpp"
#include "rpem/io/errors.hpp"
#include "rpem/sim/drive_simulator.hpp"

namespace rpem::daemon {
namespace {

sim::Scenario load_demo_or_file(const std::string& spec) {
  if (spec == "builtin:rpemd-demo") return sim::parse_scenario(builtin_demo_scenario_text(), "<built-in rpemd-demo>", "");
  return sim::load_scenario(spec);
}

class SimSampleSource final : public SampleSource {
 public:
  SimSampleSource(bool loop, std::shared_ptr<const sim::Scenario> scenario) : loop_(loop), scenario_(std::move(scenario)) {}

  void run(const std::atomic<bool>& stop, SourceOutput& out) override {
    // The drive produces its samples in 1 ms batches, in step with the wall clock: every sample whose
    // drive time has passed is pushed. On restart (loop) the drive time carries on.
    constexpr std::int64_t kBatchNs = 1'000'000;
    auto drive = std::make_unique<sim::DriveSimulator>(*scenario_);
    const std::int64_t wall_start = core::now_ns(CLOCK_MONOTONIC);
    std::int64_t target = wall_start;
    std::int64_t offset_ns = 0;
    std::int64_t last_t = 0;
    io::DriveLogRow row;
    sim::TruthRow truth;
    bool have_row = false;
    while (!stop.load(std::memory_order_relaxed)) {
      target += kBatchNs;
      core::sleep_until_ns(CLOCK_MONOTONIC, target);
      const std::int64_t elapsed = target - wall_start;
      while (true) {
        if (!have_row) {
          if (!drive->next(row, truth)) {
            if (!loop_) return;
            offset_ns = last_t + drive->period_ns();
            drive = std::make_unique<sim::DriveSimulator>(*scenario_);
            continue;
          }
          row.sample.t_ns += offset_ns;
          have_row = true;
        }
        if (row.sample.t_ns > elapsed) break;
        out.push(row.sample);
        last_t = row.sample.t_ns;
        have_row = false;
      }
      if (out.report_due(target)) {
        SourceReport r;
        r.has_truth = true;
        r.truth_psi_m_Wb = truth.parameters.psi_m_Wb;
        r.truth_r_s_Ohm = truth.parameters.r_s_Ohm;
        r.truth_t_magnet_C = truth.t_magnet_C;
        r.truth_t_winding_C = truth.t_winding_C;
        out.report(r, target);
      }
    }
  }
  [[nodiscard]] std::string name() const override { return scenario_->name; }

 private:
  bool loop_;
  std::shared_ptr<const sim::Scenario> scenario_;
};

}  // namespace

SimSource::Options SimSource::parse(io::YamlMap& section, const std::string& base_dir) {
  Options o;
  o.scenario = section.text_or("scenario", o.scenario);
  if (o.scenario.rfind("builtin:", 0) != 0 && std::filesystem::path(o.scenario).is_relative()) {
    o.scenario = (std::filesystem::path(base_dir) / o.scenario).lexically_normal().string();
  }
  o.loop = section.boolean_or("loop", o.loop);
  section.finish();
  // Read now, so that a scenario rpemd cannot run stops it at start (and --check-config) as the rest of the file does.
  try {
    o.scenario_read = ReadAtParse<sim::Scenario>(load_demo_or_file(o.scenario));
  } catch (const io::InputError& e) {
    section.fail("scenario", std::string("cannot be run: ") + e.what());
  }
  return o;
}

std::unique_ptr<SampleSource> SimSource::make(const Options& options) {
  auto scenario = options.scenario_read.has_value()
                      ? options.scenario_read.shared()
                      : std::make_shared<const sim::Scenario>(load_demo_or_file(options.scenario));
  return std::make_unique<SimSampleSource>(options.loop, std::move(scenario));
}

}  // namespace rpem::daemon
