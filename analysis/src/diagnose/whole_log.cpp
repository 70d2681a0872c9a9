#include "rpem/analysis/diagnose/whole_log.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/analysis/diagnose/verdict.hpp"
#include "rpem/core/conditioner.hpp"
#include "rpem/core/non_finite.hpp"
#include "rpem/core/units.hpp"

namespace rpem::analysis {
namespace {

using core::kNaN;
/// The figures' ranges start from these (no sample: the range is then the figure's default).
constexpr double kFar = 1e300;

/// The temperature the figure draws against at sample k (the winding's if logged, else the magnet's), as the
/// models take it (held between a slow sensor's readings).
double drawn_temperature(const LogData& log, const EffectContext& context, std::size_t k) {
  return (context.t_winding.logged ? log.samples.t_winding_held_C(k) : log.samples.t_magnet_held_C(k)).value_or(kNaN);
}

/// The figures' sums of one block of the comparison's pass: its time bins from `first_bin` on, the map's
/// cells, the temperature's bins, its samples in the overlay's window.
struct BlockFigures {
  std::size_t first_bin = 0;
  std::vector<std::array<double, 5>> bins;  ///< Σ|ε|² before, after, Σε_d, Σε_q before, count
  std::vector<std::array<double, 3>> map;
  std::vector<std::array<double, 5>> temperature;
  std::vector<std::array<double, 7>> overlay;
};

}  // namespace

double speed_rpm(const EffectContext& context, double omega_el_rad_s) {
  return core::rad_s_to_rpm(omega_el_rad_s) / context.machine.rated.pole_pairs;
}

BaselinePass baseline_pass(const ModelReplay& replay, const EffectContext& context, const ExtendedModel& baseline) {
  const LogData& log = replay.log();
  const std::vector<int> blocks = replay.blocks(Blocks::kAll);
  const std::vector<ExtendedModel> models = {baseline};
  struct Block {
    SecondDifferences differences;
    std::vector<double> squared;  ///< |ε|² of the baseline per sample of the block (0 where not predicted)
    BaselinePass ranges;
  };
  std::vector<Block> per_block(blocks.size());
  replay.for_blocks(blocks, [&](std::size_t i, int b) {
    Block& out = per_block[i];
    const std::size_t first = log.block_first[static_cast<std::size_t>(b)];
    out.squared.assign(log.block_first[static_cast<std::size_t>(b) + 1] - first, 0.0);
    BaselinePass& r = out.ranges;
    r.speed_lo_rpm = r.i_q_lo_A = r.temperature_lo_C = kFar;
    r.speed_hi_rpm = r.i_q_hi_A = r.temperature_hi_C = -kFar;
    replay.replay_block(b, models, [&](std::size_t k, std::span<const ModelSample> m) {
      out.differences.add(log, k, m[0]);
      if (!m[0].valid) return;
      out.squared[k - first] = m[0].residual_A.squaredNorm();
      const double speed = speed_rpm(context, log.samples.omega_el_rad_s(k)), i_q = log.logged_i_dq_A(k)[1];
      r.speed_lo_rpm = std::min(r.speed_lo_rpm, speed);
      r.speed_hi_rpm = std::max(r.speed_hi_rpm, speed);
      r.i_q_lo_A = std::min(r.i_q_lo_A, i_q);
      r.i_q_hi_A = std::max(r.i_q_hi_A, i_q);
      const double t = drawn_temperature(log, context, k);
      if (!std::isfinite(t)) return;
      r.temperature_lo_C = std::min(r.temperature_lo_C, t);
      r.temperature_hi_C = std::max(r.temperature_hi_C, t);
    });
  });

  BaselinePass out;
  out.speed_lo_rpm = out.i_q_lo_A = out.temperature_lo_C = kFar;
  out.speed_hi_rpm = out.i_q_hi_A = out.temperature_hi_C = -kFar;
  SecondDifferences differences;
  for (Block& b : per_block) {
    differences.append(b.differences);
    b.differences = SecondDifferences();
    out.speed_lo_rpm = std::min(out.speed_lo_rpm, b.ranges.speed_lo_rpm);
    out.speed_hi_rpm = std::max(out.speed_hi_rpm, b.ranges.speed_hi_rpm);
    out.i_q_lo_A = std::min(out.i_q_lo_A, b.ranges.i_q_lo_A);
    out.i_q_hi_A = std::max(out.i_q_hi_A, b.ranges.i_q_hi_A);
    out.temperature_lo_C = std::min(out.temperature_lo_C, b.ranges.temperature_lo_C);
    out.temperature_hi_C = std::max(out.temperature_hi_C, b.ranges.temperature_hi_C);
  }
  out.noise_floor = std::move(differences).noise_floor(log);

  // The overlay's window: transient logs the 0.1 s where the configuration errs most; steady state the whole log.
  const std::size_t n = log.size();
  out.overlay_first = 0;
  out.overlay_last = n;
  if (log.mode == ModelMode::kTransient) {
    const std::size_t window = std::max<std::size_t>(2, static_cast<std::size_t>(0.1 / std::max(log.median_dt_s, 1e-9)));
    auto squared = [&, i = std::size_t{0}](std::size_t k) mutable {  // blocks in order; samples in none count 0
      while (i < blocks.size() && k >= log.block_first[static_cast<std::size_t>(blocks[i]) + 1]) ++i;
      if (i == blocks.size() || k < log.block_first[static_cast<std::size_t>(blocks[i])]) return 0.0;
      return per_block[i].squared[k - log.block_first[static_cast<std::size_t>(blocks[i])]];
    };
    auto trailing = squared;
    double best = -1.0, sum = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      sum += squared(k);
      if (k >= window) sum -= trailing(k - window);
      if (k + 1 >= window && sum > best) {
        best = sum;
        out.overlay_first = k + 1 - window;
      }
    }
    out.overlay_last = std::min(n, out.overlay_first + window);
  }
  return out;
}

namespace {

/// The blocks' figure sums merged in block order into the figures' time bins, operating-plane map, temperature
/// bins and overlay. Time bins: the log's own columns over every sample of the bin, the residuals over those
/// both models predict.
void merge_figures(const LogData& log, const EffectContext& context, const std::vector<BlockFigures>& parts,
                   std::size_t per_bin, FigureData& figures) {
  const std::size_t n = log.size();
  constexpr int kCells = FigureData::kMapX * FigureData::kMapY;
  figures = FigureData();
  std::vector<std::array<double, 5>> bins((n + per_bin - 1) / per_bin, {0.0, 0.0, 0.0, 0.0, 0.0});
  figures.map.assign(kCells, {0.0, 0.0, 0.0});
  figures.temperature.assign(FigureData::kTemperatureBins, {0.0, 0.0, 0.0, 0.0, 0.0});
  for (const BlockFigures& f : parts) {
    for (std::size_t j = 0; j < f.bins.size(); ++j) {
      for (int c = 0; c < 5; ++c)
        bins[f.first_bin + j][static_cast<std::size_t>(c)] += f.bins[j][static_cast<std::size_t>(c)];
    }
    for (std::size_t c = 0; c < f.map.size(); ++c) {
      for (int v = 0; v < 3; ++v) figures.map[c][static_cast<std::size_t>(v)] += f.map[c][static_cast<std::size_t>(v)];
    }
    for (std::size_t c = 0; c < f.temperature.size(); ++c) {
      for (int v = 0; v < 5; ++v)
        figures.temperature[c][static_cast<std::size_t>(v)] += f.temperature[c][static_cast<std::size_t>(v)];
    }
    figures.overlay.insert(figures.overlay.end(), f.overlay.begin(), f.overlay.end());
  }
  for (std::size_t start = 0, j = 0; start < n; start += per_bin, ++j) {
    double t = 0, sp = 0, iq = 0, temp = 0, temp_readings = 0, all_samples = 0;
    for (std::size_t k = start; k < std::min(n, start + per_bin); ++k) {
      t += log.t_s(k);
      sp += speed_rpm(context, log.samples.omega_el_rad_s(k));
      iq += log.logged_i_dq_A(k)[1];
      all_samples += 1;
      // The bin's mean of the readings it has: a slow sensor reads on few rows (docs/drive-log.md).
      const double reading = log.samples.t_winding_C(k).value_or(log.samples.t_magnet_C(k).value_or(kNaN));
      if (std::isnan(reading)) continue;
      temp += reading;
      temp_readings += 1;
    }
    const auto& r = bins[j];
    const double cnt = r[4];
    figures.time.push_back({t / all_samples, sp / all_samples, iq / all_samples, cnt != 0.0 ? std::sqrt(r[0] / cnt) : kNaN,
                            cnt != 0.0 ? std::sqrt(r[1] / cnt) : kNaN, cnt != 0.0 ? r[2] / cnt : kNaN,
                            cnt != 0.0 ? r[3] / cnt : kNaN, temp_readings > 0 ? temp / temp_readings : kNaN});
  }
}

}  // namespace

void comparison_pass(const ModelReplay& replay, const EffectContext& context, const ExtendedModel& baseline,
                     const ExtendedModel& extended, const BaselinePass& pass, ResidualStatistics& statistics,
                     FigureData& figures) {
  const LogData& log = replay.log();
  const std::size_t n = log.size();
  const std::size_t per_bin = std::max<std::size_t>(1, n / FigureData::kTimeBins);
  const std::vector<int> blocks = replay.blocks(Blocks::kAll);
  const std::vector<ExtendedModel> models = {baseline, extended};
  const double s_lo = pass.speed_lo_rpm, q_lo = pass.i_q_lo_A;
  const double s_hi = pass.speed_hi_rpm <= s_lo ? s_lo + 1.0 : pass.speed_hi_rpm;
  const double q_hi = pass.i_q_hi_A <= q_lo ? q_lo + 1.0 : pass.i_q_hi_A;
  const double t_lo = pass.temperature_lo_C, t_hi = pass.temperature_hi_C;
  constexpr int kCells = FigureData::kMapX * FigureData::kMapY;

  std::vector<ResidualSums> sums(blocks.size(), ResidualSums(log, context));
  std::vector<BlockFigures> parts(blocks.size());
  replay.for_blocks(blocks, [&](std::size_t i, int b) {
    BlockFigures& f = parts[i];
    const std::size_t first = log.block_first[static_cast<std::size_t>(b)],
                      end = log.block_first[static_cast<std::size_t>(b) + 1];
    f.first_bin = first / per_bin;
    f.bins.assign((end - 1) / per_bin - f.first_bin + 1, {0.0, 0.0, 0.0, 0.0, 0.0});
    f.map.assign(kCells, {0.0, 0.0, 0.0});
    f.temperature.assign(FigureData::kTemperatureBins, {0.0, 0.0, 0.0, 0.0, 0.0});
    replay.replay_block(b, models, [&](std::size_t k, std::span<const ModelSample> m) {
      if (!m[0].valid || !m[1].valid) return;
      const core::Vec2 &rb = m[0].residual_A, &ra = m[1].residual_A;
      sums[i].add(k, rb, ra);
      auto& bin = f.bins[k / per_bin - f.first_bin];
      bin[0] += rb.squaredNorm();
      bin[1] += ra.squaredNorm();
      bin[2] += rb[0];
      bin[3] += rb[1];
      bin[4] += 1.0;
      const double speed = speed_rpm(context, log.samples.omega_el_rad_s(k));
      const core::Vec2 i_dq = log.logged_i_dq_A(k);
      const int x = std::min(FigureData::kMapX - 1, static_cast<int>((speed - s_lo) / (s_hi - s_lo) * FigureData::kMapX));
      const int y = std::min(FigureData::kMapY - 1, static_cast<int>((i_dq[1] - q_lo) / (q_hi - q_lo) * FigureData::kMapY));
      auto& cell = f.map[static_cast<std::size_t>(y) * FigureData::kMapX + static_cast<std::size_t>(x)];
      cell[0] += rb.squaredNorm();
      cell[1] += ra.squaredNorm();
      cell[2] += 1.0;
      if (const double t = drawn_temperature(log, context, k); std::isfinite(t)) {
        const int tb = std::min(FigureData::kTemperatureBins - 1,
                                static_cast<int>((t - t_lo) / std::max(t_hi - t_lo, 1e-9) * FigureData::kTemperatureBins));
        auto& s = f.temperature[static_cast<std::size_t>(tb)];
        s[0] += 1.0;
        s[1] += rb[0];
        s[2] += rb[1];
        s[3] += ra[0];
        s[4] += ra[1];
      }
      if (k >= pass.overlay_first && k < pass.overlay_last) {
        f.overlay.push_back(
            {log.t_s(k), i_dq[0], i_dq[1], m[0].model_A[0], m[0].model_A[1], m[1].model_A[0], m[1].model_A[1]});
      }
    });
  });

  ResidualSums all(log, context);
  for (const ResidualSums& s : sums) all.merge(s);
  statistics = all.statistics();

  merge_figures(log, context, parts, per_bin, figures);
  figures.speed_lo_rpm = s_lo;
  figures.speed_hi_rpm = s_hi;
  figures.i_q_lo_A = q_lo;
  figures.i_q_hi_A = q_hi;
  figures.temperature_lo_C = t_lo;
  figures.temperature_hi_C = t_hi;
}

}  // namespace rpem::analysis
