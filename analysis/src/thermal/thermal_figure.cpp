#include "rpem/analysis/thermal/thermal_figure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "rpem/analysis/gnuplot.hpp"
#include "rpem/core/non_finite.hpp"
#include "rpem/io/csv_table.hpp"
#include "rpem/io/errors.hpp"

namespace rpem::analysis {
namespace {

using core::kNaN;

/// The estimate's value at time t by linear interpolation between its rows (NaN outside them).
double at(const std::vector<double>& t, const std::vector<double>& v, double when) {
  const auto it = std::lower_bound(t.begin(), t.end(), when);
  if (it == t.end()) return kNaN;
  const std::size_t k = static_cast<std::size_t>(it - t.begin());
  if (*it == when) return v[k];
  if (k == 0) return kNaN;
  const double a = (when - t[k - 1]) / (t[k] - t[k - 1]);
  return v[k - 1] + a * (v[k] - v[k - 1]);
}

/// A node's panel; returns the 2σ coverage of the measured points.
double panel(GnuplotFigure& fig, const io::CsvTable& est, const io::CsvTable* measured, const std::string& node,
             const std::string& measured_column, double judged_after_s) {
  const std::vector<double>& t = est.column("t");
  const std::vector<double>& fused = est.column("t_" + node + "_fused_C");
  const std::vector<double>& sd = est.column("t_" + node + "_fused_sd_C");
  const std::vector<double>& alone = est.column("T_" + node + "_rpem");
  // RPEM alone is the estimate's temperature from its first adaptation on (held where it does not adapt): before
  // it, the column is the law's value at the configured start, which nothing has observed.
  // (A CSV without the column, written by hand: every row counts.)
  const std::string active_column = node == "magnet" ? "psi_m_active" : "r_s_active";
  std::size_t first_adapted = 0;
  if (est.has(active_column)) {
    const std::vector<double>& active = est.column(active_column);
    first_adapted = static_cast<std::size_t>(std::find(active.begin(), active.end(), 1.0) - active.begin());
  }
  // At most ~4000 points per curve: the figure, not the data, is the product.
  const std::size_t stride = std::max<std::size_t>(1, t.size() / 4000);
  DataBlock e{node + "_est", std::vector<std::vector<double>>(5)};
  for (std::size_t k = 0; k < t.size(); k += stride) {
    for (auto [c, v] : {std::pair{0, t[k]},
                        {1, fused[k]},
                        {2, fused[k] - 2.0 * sd[k]},
                        {3, fused[k] + 2.0 * sd[k]},
                        {4, k >= first_adapted ? alone[k] : kNaN}}) {
      e.columns[static_cast<std::size_t>(c)].push_back(std::isfinite(v) ? v : kNaN);
    }
  }
  fig.add_data(e);
  double covered = 0.0, counted = 0.0;
  const std::string parameter = node == "magnet" ? "ψm" : "R_s";
  std::string plot = "plot $" + node +
                     "_est u 1:3:4 w filledcurves fc rgb '#c6dbef' title 'fused ±2σ', "
                     "$" +
                     node + "_est u 1:2 w l lw 2 lc rgb '#08519c' title 'fused'";
  if (first_adapted < t.size()) {
    plot += ", $" + node + "_est u 1:5 w l dt 2 lc rgb '#636363' title " +
            gp_quote("RPEM alone (from " + parameter + "'s first adaptation, held)") + " noenhanced";
  }
  if (measured != nullptr && measured->has(measured_column)) {
    const std::vector<double>& tm = measured->column("t");
    const std::vector<double>& vm = measured->column(measured_column);
    DataBlock m{node + "_meas", std::vector<std::vector<double>>(2)};
    const std::size_t mstride = std::max<std::size_t>(1, tm.size() / 4000);
    for (std::size_t k = 0; k < tm.size(); ++k) {
      if (k % mstride == 0) {
        m.columns[0].push_back(tm[k]);
        m.columns[1].push_back(vm[k]);
      }
      const double f = at(t, fused, tm[k]), s = at(t, sd, tm[k]);
      if (!std::isfinite(f) || !std::isfinite(s) || !std::isfinite(vm[k]) || tm[k] <= judged_after_s) continue;
      counted += 1.0;
      covered += std::abs(vm[k] - f) <= 2.0 * s ? 1.0 : 0.0;
    }
    fig.add_data(m);
    // A column's name is text, not markup: gnuplot's enhanced mode would set `T_magnet` as T with the subscript m.
    plot += ", $" + node + "_meas u 1:2 w l lw 1.5 lc rgb '#cb181d' title " +
            gp_quote("measured (" + measured_column + ")") + " noenhanced";
  }
  fig.add_line(
      "set title " +
      gp_quote(first_adapted < t.size() ? node : node + " (RPEM alone: " + parameter + " never adapted in this log)") +
      " noenhanced");
  fig.add_line("unset arrow");
  if (judged_after_s > 0.0) {
    fig.add_line("set arrow from " + std::to_string(judged_after_s) + ", graph 0 to " + std::to_string(judged_after_s) +
                 ", graph 1 nohead dt 3 lc rgb 'black'");
  }
  fig.add_line(plot);
  return counted > 0.0 ? covered / counted : kNaN;
}

/// The measured times against the estimate's (both increasing, non-empty): a thermocouple log that starts at 0
/// beside an estimate on VESC Tool's seconds since midnight shares no time, and would judge nothing, silently.
void check_times_overlap(const ThermalFigureInput& in, const std::vector<double>& t_est, const std::vector<double>& t_m) {
  if (t_est.empty() || t_m.empty() || (t_m.front() <= t_est.back() && t_m.back() >= t_est.front())) return;
  char text[320];
  std::snprintf(text, sizeof text,
                "its times (%.6g to %.6g s) share none with the estimate's (%.6g to %.6g s, %s): both need one clock "
                "(shift the measured t by the difference of their starts)",
                t_m.front(), t_m.back(), t_est.front(), t_est.back(), in.estimate_csv.c_str());
  throw io::DataError(in.measured_csv, 2, 0, "column t", text);
}

}  // namespace

ThermalFigureCoverage write_thermal_figure(const std::string& png_path, const ThermalFigureInput& in) {
  const io::CsvTable est = io::CsvTable::read(in.estimate_csv, /*allow_nan=*/true);
  if (!est.has("T_magnet_rpem")) {
    throw io::DataError(in.estimate_csv, 1, 0, "header", "no thermal columns: write it with `rpem estimate --thermal`");
  }
  est.require_increasing("t");  // at() interpolates in it
  // Measured temperatures may be NaN where a reading is missing (not plotted, not counted); their times may not.
  std::optional<io::CsvTable> measured;
  if (!in.measured_csv.empty()) {
    measured = io::CsvTable::read(in.measured_csv, /*allow_nan=*/true);
    for (const std::string& c : {std::string("t"), in.magnet_column, in.winding_column}) {
      if (!measured->has(c)) throw io::DataError(in.measured_csv, 1, 0, c, "column missing from the header");
    }
    measured->require_increasing("t");
    check_times_overlap(in, est.column("t"), measured->column("t"));
  }
  GnuplotFigure fig(png_path, 1400, 800);
  fig.add_line("set multiplot layout 2,1");
  // The key beside the panels: inside, the band reaches whichever corner it stands in and hides it or the data.
  // Both panels keep the keys' margin, so that their time axes align.
  fig.add_line("set xlabel 't [s]'; set ylabel 'T [°C]'; set key outside right top; set grid");
  fig.add_line("set lmargin at screen 0.06; set rmargin at screen 0.72");
  ThermalFigureCoverage c;
  const io::CsvTable* m = measured ? &*measured : nullptr;
  c.magnet = panel(fig, est, m, "magnet", in.magnet_column, in.judged_after_s);
  c.winding = panel(fig, est, m, "winding", in.winding_column, in.judged_after_s);
  fig.add_line("unset multiplot");
  fig.render();
  return c;
}

}  // namespace rpem::analysis
