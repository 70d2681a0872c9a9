// The figures of a diagnosis (docs/diagnose.md, "Reading the report"): residual against time with the
// operating profile, residual maps over the speed–current plane, harmonic content, the dead-time
// signature or the residual against temperature, measured against modelled currents, and the estimates
// with the configuration and the extended model. Before (the configuration) and after (extended) side by side throughout.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <limits>

#include "../median.hpp"
#include "rpem/analysis/diagnose/diagnose_output.hpp"
#include "rpem/analysis/gnuplot.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/core/conditioner.hpp"
#include "rpem/core/non_finite.hpp"
#include "rpem/core/units.hpp"
#include "rpem/io/number_format.hpp"

namespace rpem::analysis {
namespace {

using core::kNaN;

/// The temperature column a figure draws against (the winding's if logged), and whether it varies.
const TemperatureColumn& drawn_temperature(const Diagnosis& d) {
  return d.context.t_winding.logged ? d.context.t_winding : d.context.t_magnet;
}
bool temperature_varies(const Diagnosis& d) {
  const TemperatureColumn& c = drawn_temperature(d);
  return c.logged && c.span_K >= 1.0;
}

/// A folder's sessions (LogData::session_first), on every figure against time: the title's note, and a dashed line
/// where each session after the first starts, for the starts inside [t_from_s, t_to_s] (the figure's time axis).
std::string sessions_note(const LogData& log) { return log.sessions() > 1 ? " (dashed: a session starts)" : ""; }
void mark_session_starts(GnuplotFigure& fig, const LogData& log, double t_from_s, double t_to_s) {
  for (std::size_t j = 1; j < log.sessions(); ++j) {
    const double t_s = log.t_s(log.session_first[j]);
    if (t_s < t_from_s || t_s > t_to_s) continue;
    char arrow[160];
    std::snprintf(arrow, sizeof arrow, "set arrow from %.9g, graph 0 to %.9g, graph 1 nohead dt 2 lc rgb 'black'", t_s, t_s);
    fig.add_line(arrow);
  }
}
/// The whole log's time axis.
void mark_session_starts(GnuplotFigure& fig, const LogData& log) {
  if (log.size() > 0) mark_session_starts(fig, log, log.t_s(0), log.t_s(log.size() - 1));
}

/// Time-binned profile and residual statistics (every sample for short logs).
DataBlock time_bins(const Diagnosis& d) {
  DataBlock b{"time", std::vector<std::vector<double>>(8)};  // t, speed, i_q, rms before, rms after, mean d, mean q, T
  for (const auto& bin : d.figures.time) {
    for (std::size_t c = 0; c < 8; ++c) b.columns[c].push_back(bin[c]);
  }
  return b;
}

std::string residual_time(const std::string& dir, const Diagnosis& d) {
  const bool temps = temperature_varies(d);
  GnuplotFigure fig(dir + "/residual_time.png", 1400, 1000);
  fig.add_data(time_bins(d));
  fig.add_line("set multiplot layout 3,1 title 'What the model gets wrong, against time" + sessions_note(*d.log) +
               "' noenhanced");
  fig.add_line("set grid; set xlabel 't [s]'; set key outside right");
  mark_session_starts(fig, *d.log);
  fig.add_line("set title 'operating profile'; set ylabel 'speed [rpm]'; set y2label 'i_q [A]" +
               std::string(temps ? ", temperature [°C]" : "") + "'; set y2tics; set ytics nomirror");
  fig.add_line(std::string("plot $time u 1:2 w l lw 2 t 'speed', '' u 1:3 axes x1y2 w l lw 2 t 'i_q'") +
               (temps ? ", '' u 1:8 axes x1y2 w l lw 2 t 'T'" : ""));
  fig.add_line("unset y2tics; unset y2label; set ytics mirror");
  fig.add_line("set title 'residual RMS (logged − model)'; set ylabel '|ε| [A]'; set logscale y");
  fig.add_line(
      "plot $time u 1:4 w l lw 2 lc rgb '#d62728' t 'configuration', '' u 1:5 w l lw 2 lc rgb '#2ca02c' t 'extended model'");
  fig.add_line("unset logscale y; set title 'mean residual of the configuration'; set ylabel 'ε [A]'");
  fig.add_line("plot $time u 1:6 w l lw 2 t 'ε_d', '' u 1:7 w l lw 2 t 'ε_q'");
  fig.add_line("unset multiplot");
  fig.render();
  return "residual_time.png";
}

std::string residual_map(const std::string& dir, const Diagnosis& d) {
  constexpr int kX = FigureData::kMapX, kY = FigureData::kMapY;
  const FigureData& f = d.figures;
  const double s_lo = f.speed_lo_rpm, s_hi = f.speed_hi_rpm, q_lo = f.i_q_lo_A, q_hi = f.i_q_hi_A;
  DataBlock b{"map", std::vector<std::vector<double>>(4)};
  double lo = 1e300, hi = 0.0;  // one colour scale for both maps, so the improvement shows
  bool exact = false;           // a cell the model fits exactly (RMS 0: noise-free data) has no place on a log scale
  for (const auto& cell : f.map) {
    if (cell[2] == 0.0) continue;
    for (double v : {std::sqrt(cell[0] / cell[2]), std::sqrt(cell[1] / cell[2])}) {
      if (v > 0.0) lo = std::min(lo, v);
      exact = exact || v == 0.0;
      hi = std::max(hi, v);
    }
  }
  const bool log_scale = hi > 0.0;
  // An exact cell is drawn at the scale's low end, and the title says so.
  const auto rms = [&](double sum_sq, double n) {
    if (n == 0.0) return kNaN;
    const double v = std::sqrt(sum_sq / n);
    return v > 0.0 || !log_scale ? v : lo;
  };
  for (int y = 0; y < kY; ++y) {
    for (int x = 0; x < kX; ++x) {
      const auto& cell = f.map[static_cast<std::size_t>(y) * kX + static_cast<std::size_t>(x)];
      b.columns[0].push_back(s_lo + (x + 0.5) * (s_hi - s_lo) / kX);
      b.columns[1].push_back(q_lo + (y + 0.5) * (q_hi - q_lo) / kY);
      b.columns[2].push_back(rms(cell[0], cell[2]));
      b.columns[3].push_back(rms(cell[1], cell[2]));
    }
  }
  GnuplotFigure fig(dir + "/residual_map.png", 1400, 600);
  fig.add_data(std::move(b));
  fig.add_line(std::string("set multiplot layout 1,2 title 'Residual RMS over the operating plane (speed × i_q)") +
               (exact && log_scale ? "; cells fitted exactly (RMS 0) at the scale's low end" : "") + "' noenhanced");
  fig.add_line(std::string("set xlabel 'speed [rpm]'; set ylabel 'i_q [A]'; set cblabel '|ε| RMS [A]'") +
               (log_scale ? "; set logscale cb" : ""));
  fig.add_line("set palette defined (0 '#313695', 1 '#74add1', 2 '#ffffbf', 3 '#f46d43', 4 '#a50026')");
  fig.add_line("set view map; set datafile missing NaN");
  if (hi > lo) {
    std::string range = "set cbrange [";  // round-trip digits: std::to_string's six decimals made 3e-9 a zero
    io::append_number(range, lo);
    range += ':';
    io::append_number(range, hi);
    fig.add_line(range + "]");
  } else if (!log_scale) {
    fig.add_line("set cbrange [0:1]");  // every cell exact: a scale that starts at zero
  }
  fig.add_line("set title 'configuration'; plot $map u 1:2:3 w points pt 5 ps 2.2 lc palette notitle");
  fig.add_line("set title 'extended model'; plot $map u 1:2:4 w points pt 5 ps 2.2 lc palette notitle");
  fig.add_line("unset multiplot");
  fig.render();
  return "residual_map.png";
}

std::string harmonics(const std::string& dir, const Diagnosis& d) {
  DataBlock b{"h", std::vector<std::vector<double>>(3)};
  for (const HarmonicContent& h : d.statistics.harmonics) {
    b.columns[0].push_back(h.order);
    b.columns[1].push_back(std::max(h.amplitude_A.before, 1e-6));
    b.columns[2].push_back(std::max(h.amplitude_A.after, 1e-6));
  }
  GnuplotFigure fig(dir + "/harmonics.png", 1000, 500);
  fig.add_data(std::move(b));
  fig.add_line("set title 'Residual content at harmonics of the electrical angle (samples in motion)' noenhanced");
  fig.add_line("set xlabel 'harmonic order (dq frame; 0 = mean)'; set ylabel 'amplitude [A]'; set logscale y; set grid");
  fig.add_line("set style fill solid 0.8; set boxwidth 0.35; set xtics 1");
  fig.add_line(
      "plot $h u ($1-0.18):2 w boxes lc rgb '#d62728' t 'configuration', '' u ($1+0.18):3 w boxes lc rgb '#2ca02c' t 'extended model'");
  fig.render();
  return "harmonics.png";
}

std::string phase_sign(const std::string& dir, const Diagnosis& d) {
  DataBlock b{"p", std::vector<std::vector<double>>(5)};
  for (std::size_t x = 0; x < d.statistics.phase_signs.size(); ++x) {
    const PhaseSignStatistics& p = d.statistics.phase_signs[x];
    b.columns[0].push_back(static_cast<double>(x));
    b.columns[1].push_back(p.mean_when_positive_A.before);
    b.columns[2].push_back(p.mean_when_negative_A.before);
    b.columns[3].push_back(p.mean_when_positive_A.after);
    b.columns[4].push_back(p.mean_when_negative_A.after);
  }
  GnuplotFigure fig(dir + "/phase_sign.png", 1000, 500);
  fig.add_data(std::move(b));
  fig.add_line(
      "set title 'Mean phase residual by the sign of the phase current (dead time pulls it against the current)' noenhanced");
  fig.add_line("set ylabel 'mean residual [A]'; set xtics (\"a\" 0, \"b\" 1, \"c\" 2); set grid; set xrange [-0.6:2.6]");
  fig.add_line("set style fill solid 0.8; set boxwidth 0.18");
  fig.add_line(
      "plot $p u ($1-0.3):2 w boxes lc rgb '#d62728' t 'configuration, i > 0', '' u ($1-0.1):3 w boxes lc rgb '#ff9896' t 'configuration, i < 0', "
      "'' u ($1+0.1):4 w boxes lc rgb '#2ca02c' t 'extended, i > 0', '' u ($1+0.3):5 w boxes lc rgb '#98df8a' t 'extended, i < 0'");
  fig.render();
  return "phase_sign.png";
}

std::string residual_vs_temperature(const std::string& dir, const Diagnosis& d) {
  // Binned over the temperature's range: the mean residual per bin, so a trend shows however long the log.
  constexpr int kBins = FigureData::kTemperatureBins;
  const bool winding = d.context.t_winding.logged;
  const double lo = d.figures.temperature_lo_C, hi = d.figures.temperature_hi_C;
  DataBlock b{"t", std::vector<std::vector<double>>(5)};  // T, eps_d before, eps_q before, eps_d after, eps_q after
  for (int i = 0; i < kBins; ++i) {
    const auto& s = d.figures.temperature[static_cast<std::size_t>(i)];
    if (s[0] == 0.0) continue;
    b.columns[0].push_back(lo + (i + 0.5) * (hi - lo) / kBins);
    for (int c = 1; c < 5; ++c) b.columns[static_cast<std::size_t>(c)].push_back(s[static_cast<std::size_t>(c)] / s[0]);
  }
  GnuplotFigure fig(dir + "/residual_temperature.png", 1000, 550);
  fig.add_data(std::move(b));
  fig.add_line(std::string("set title 'Mean residual against the ") + (winding ? "winding" : "magnet") +
               " temperature' noenhanced");
  fig.add_line(std::string("set xlabel '") + (winding ? "T_{winding}" : "T_{magnet}") +
               " [°C]'; set ylabel 'mean ε [A]'; set grid; set key outside right");
  fig.add_line(
      "plot $t u 1:2 w lp pt 7 ps 0.6 lc rgb '#d62728' t 'ε_d configuration', '' u 1:3 w lp pt 7 ps 0.6 lc rgb '#ff7f0e' t 'ε_q configuration', "
      "'' u 1:4 w lp pt 7 ps 0.6 lc rgb '#2ca02c' t 'ε_d extended', '' u 1:5 w lp pt 7 ps 0.6 lc rgb '#17becf' t 'ε_q extended'");
  fig.render();
  return "residual_temperature.png";
}

std::string overlay(const std::string& dir, const Diagnosis& d) {
  // Transient logs: the 0.1 s window where the configuration errs most; steady state: the whole log.
  DataBlock b{"o", std::vector<std::vector<double>>(7)};
  for (const auto& row : d.figures.overlay) {
    for (std::size_t c = 0; c < 7; ++c) b.columns[c].push_back(row[c]);
  }
  const std::string style = d.log->mode == ModelMode::kTransient ? "w l lw 2" : "w p pt 7 ps 0.5";
  GnuplotFigure fig(dir + "/overlay.png", 1400, 800);
  fig.add_data(std::move(b));
  fig.add_line("set multiplot layout 2,1 title 'Logged current against the configuration and the extended model" +
               sessions_note(*d.log) + "' noenhanced");
  fig.add_line("set grid; set xlabel 't [s]'; set key outside right");
  if (!d.figures.overlay.empty())
    mark_session_starts(fig, *d.log, d.figures.overlay.front()[0], d.figures.overlay.back()[0]);
  fig.add_line("set title 'd axis'; set ylabel 'i_d [A]'; plot $o u 1:2 " + style + " lc rgb 'black' t 'logged', '' u 1:4 " +
               style + " lc rgb '#d62728' t 'configuration', '' u 1:6 " + style + " lc rgb '#2ca02c' t 'extended'");
  fig.add_line("set title 'q axis'; set ylabel 'i_q [A]'; plot $o u 1:3 " + style + " lc rgb 'black' t 'logged', '' u 1:5 " +
               style + " lc rgb '#d62728' t 'configuration', '' u 1:7 " + style + " lc rgb '#2ca02c' t 'extended'");
  fig.add_line("unset multiplot");
  fig.render();
  return "overlay.png";
}

/// Each regime's colour in the timeline, in core::kRegimes' order: admitted ones green to grey, excluded ones
/// warm to black.
constexpr std::array<const char*, core::kRegimeCount> kRegimeColour{"#2ca02c", "#1f77b4", "#17becf", "#9a9a9a",
                                                                    "#ff7f0e", "#9467bd", "#d62728", "#000000"};

std::string regime_timeline(const std::string& dir, const LogData& log, const LogRegimes& regimes, int pole_pairs) {
  // Per time bin and regime, the mean speed and current amplitude of that regime's samples in the bin: a short
  // stretch in one regime shows however long the log.
  const std::size_t n = log.size();
  const std::size_t per_bin = std::max<std::size_t>(1, n / FigureData::kTimeBins);
  DataBlock b{"reg", std::vector<std::vector<double>>(4)};  // t, speed, |i|, regime
  for (std::size_t start = 0; start < n; start += per_bin) {
    std::array<std::array<double, 4>, core::kRegimeCount> sums{};  // count, t, speed, |i|
    for (std::size_t k = start; k < std::min(n, start + per_bin); ++k) {
      auto& s = sums[static_cast<std::size_t>(regimes.regime[k])];
      const core::Vec2 i = log.logged_i_dq_A(k);
      s[0] += 1.0;
      s[1] += log.t_s(k);
      s[2] += core::rad_s_to_rpm(log.samples.omega_el_rad_s(k)) / pole_pairs;
      s[3] += std::hypot(i[0], i[1]);
    }
    for (std::size_t r = 0; r < core::kRegimeCount; ++r) {
      if (sums[r][0] == 0.0) continue;
      for (int c = 0; c < 3; ++c)
        b.columns[static_cast<std::size_t>(c)].push_back(sums[r][static_cast<std::size_t>(c) + 1] / sums[r][0]);
      b.columns[3].push_back(static_cast<double>(r));
    }
  }
  std::string speed_plot, current_plot;
  for (const core::RegimeInfo& info : core::kRegimes) {
    const std::uint64_t count = regimes.counts.regimes[info.regime];
    if (count == 0) continue;
    const std::string r = std::to_string(static_cast<int>(info.regime));
    const std::string style =
        std::string(" w p pt 7 ps 0.5 lc rgb '") + kRegimeColour[static_cast<std::size_t>(info.regime)] + "'";
    const std::string title =
        std::string(" t '") + info.name + (info.excluded ? ", excluded" : "") + " (" + std::to_string(count) + ")'";
    speed_plot.append(speed_plot.empty() ? "plot" : ",").append(" $reg u 1:($4==").append(r).append("?$2:NaN)");
    speed_plot.append(style).append(title);
    current_plot.append(current_plot.empty() ? "plot" : ",").append(" $reg u 1:($4==").append(r).append("?$3:NaN)");
    current_plot.append(style).append(" notitle");
  }
  GnuplotFigure fig(dir + "/regimes.png", 1400, 800);
  fig.add_data(std::move(b));
  fig.add_line(
      std::string("set multiplot layout 2,1 title 'The log by regime: what the estimator and the fits take, and what they "
                  "leave out") +
      sessions_note(log) + "' noenhanced");
  // Regime names hold underscores (not subscripts); both panels keep the key's margin so their time axes align.
  fig.add_line("set termoption noenhanced; set grid; set xlabel 't [s]'; set key outside right; set datafile missing NaN");
  fig.add_line("set lmargin at screen 0.07; set rmargin at screen 0.78");
  mark_session_starts(fig, log);
  fig.add_line("set title 'speed'; set ylabel 'speed [rpm]'");
  fig.add_line(speed_plot);
  fig.add_line("set title 'current amplitude'; set ylabel '|i| [A]'");
  fig.add_line(current_plot);
  fig.add_line("unset multiplot");
  fig.render();
  return "regimes.png";
}

DataBlock track_block(const char* name, const ParameterTrack& t) { return {name, {t.t_s, t.psi_m_Wb, t.r_s_Ohm}}; }

/// A panel's y range for the values rows imply: their median ± 6 robust standard deviations (1.4826·MAD), widened
/// to the models' values, so that a few rows the steady-state model cannot represent (a transient inside a
/// window, an unlocked start-up too slow to judge) do not shrink the rest to a line. Empty: autoscale (no spread).
/// Steady-state logs only: the implied values are one per row of the models' tracks. `shown`: the lines plotted
/// with them (the models' values, a truth), each wholly in range.
/// `outside`: how many implied values the range leaves out.
std::string robust_yrange(const std::vector<double>& implied, std::initializer_list<const std::vector<double>*> shown,
                          std::size_t& outside) {
  std::vector<double> v;
  for (double x : implied) {
    if (std::isfinite(x)) v.push_back(x);
  }
  outside = 0;
  if (v.empty()) return "";
  const double m = median(v);
  std::vector<double> deviation(v.size());
  std::transform(v.begin(), v.end(), deviation.begin(), [m](double x) { return std::abs(x - m); });
  const double spread = 6.0 * 1.4826 * median(deviation);
  if (!(spread > 1e-6 * std::abs(m))) return "";  // no spread to speak of: gnuplot's autoscale widens a constant
  double lo = m - spread, hi = m + spread;
  for (const std::vector<double>* line : shown) {
    for (double x : *line) {
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
  }
  outside = static_cast<std::size_t>(std::count_if(v.begin(), v.end(), [&](double x) { return x < lo || x > hi; }));
  const double pad = 0.05 * (hi - lo);
  char range[96];
  std::snprintf(range, sizeof range, "set yrange [%.17g:%.17g]; ", lo - pad, hi + pad);  // exact: a range may be narrow
  return range;
}

/// A steady-state panel's title: what the rows leave out of the plotted range, if any.
std::string implied_title(const char* title, std::size_t outside) {
  return outside == 0 ? std::string(title)
                      : std::string(title) + " (" + std::to_string(outside) + " implied values beyond the range)";
}

std::string estimates(const std::string& dir, const Diagnosis& d) {
  const EstimatorComparison& c = d.estimates;
  const bool rpem = c.method == "rpem";
  const std::string style = "w l lw 2";
  GnuplotFigure fig(dir + "/estimates.png", 1400, 800);
  fig.add_data(track_block("nom", c.nominal));
  fig.add_data(track_block("ext", c.extended));
  if (!c.truth.empty()) fig.add_data(track_block("truth", c.truth));
  if (!c.implied.empty()) fig.add_data(track_block("implied", c.implied));
  // The estimates (rpem) or the models' values (steady state) against the truth given, and what the rows imply.
  auto with_truth = [&](int col) {
    const std::string n = std::to_string(col);
    std::string plots;
    if (!c.implied.empty()) plots += ", $implied u 1:" + n + " w p pt 7 ps 0.4 lc rgb 'black' t 'implied by the data'";
    if (!c.truth.empty()) plots += ", $truth u 1:" + n + " w l lw 2 dt 2 lc rgb 'black' t 'truth'";
    return plots;
  };
  fig.add_line(std::string("set multiplot layout 2,1 title '") +
               (rpem ? "RPEM estimates with the configuration and the extended model"
                     : "ψm and R_s as each model assumes them, and as each steady-state row implies them") +
               sessions_note(*d.log) + "' noenhanced");
  fig.add_line("set grid; set xlabel 't [s]'; set key outside right");
  mark_session_starts(fig, *d.log);
  std::size_t psi_outside = 0, r_outside = 0;
  const std::string psi_range =
      rpem ? ""
           : robust_yrange(c.implied.psi_m_Wb, {&c.nominal.psi_m_Wb, &c.extended.psi_m_Wb, &c.truth.psi_m_Wb}, psi_outside);
  const std::string r_range =
      rpem ? "" : robust_yrange(c.implied.r_s_Ohm, {&c.nominal.r_s_Ohm, &c.extended.r_s_Ohm, &c.truth.r_s_Ohm}, r_outside);
  fig.add_line(psi_range + "set title " + gp_quote(implied_title("magnet flux linkage", psi_outside)) +
               "; set ylabel 'ψm [Wb]'; plot $nom u 1:2 " + style + " lc rgb '#d62728' t 'configuration', $ext u 1:2 " +
               style + " lc rgb '#2ca02c' t 'extended'" + with_truth(2));
  fig.add_line("set autoscale y; " + r_range + "set title " + gp_quote(implied_title("stator resistance", r_outside)) +
               "; set ylabel 'R_s [Ω]'; plot $nom u 1:3 " + style + " lc rgb '#d62728' t 'configuration', $ext u 1:3 " +
               style + " lc rgb '#2ca02c' t 'extended'" + with_truth(3));
  fig.add_line("unset multiplot");
  fig.render();
  return "estimates.png";
}

}  // namespace

std::vector<std::string> write_diagnose_figures(const std::string& dir, const Diagnosis& d) {
  std::vector<std::string> out = {residual_time(dir, d),
                                  regime_timeline(dir, *d.log, d.regimes, d.context.machine.rated.pole_pairs),
                                  residual_map(dir, d), overlay(dir, d)};
  if (!d.statistics.harmonics.empty()) out.push_back(harmonics(dir, d));
  if (!d.statistics.phase_signs.empty()) out.push_back(phase_sign(dir, d));
  if (temperature_varies(d)) out.push_back(residual_vs_temperature(dir, d));  // a constant axis shows nothing
  if (!d.estimates.nominal.empty()) out.push_back(estimates(dir, d));
  return out;
}

std::string write_regime_timeline(const std::string& dir, const LogData& log, const LogRegimes& regimes, int pole_pairs) {
  return regime_timeline(dir, log, regimes, pole_pairs);
}

}  // namespace rpem::analysis
