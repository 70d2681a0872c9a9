// The paper's cases. Every setting the paper leaves open is chosen here once, and explained in
// docs/reproduction.md ("Choices").
#include "rpem/analysis/reproduction.hpp"

#include "rpem/core/machine.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::analysis {
namespace {

constexpr double kRatedRpm = 1000.0;
constexpr double kRatedTorqueNm = 32.6;  // = T_b of our base (docs/per-unit.md)

/// Section V: the Zynq ERTS — switching inverter at 4 kHz, 125 µs control, imposed speed, torque
/// control, nearly ideal sensing. A 565 V link (rectified 400 V) because 0.4–0.8 pu
/// cannot be reached on the bench's 220 V with ψm = 1.14 Wb.
sim::Scenario erts(double n_pu, double tau_pu, double duration_s) {
  sim::Scenario s = sim::paper_scenario();
  s.name = "erts";
  s.duration_s = duration_s;
  s.seed = 2022;
  s.inverter.model = sim::InverterModel::kSwitching;  // integrated from edge to edge (the ERTS: 1 µs steps)
  s.sensors.current_noise_A = 0.005;
  s.sensors.current_lsb_A = 0.005;
  s.sensors.encoder_counts = 65536;
  s.signal(sim::Quantity::kSpeed) = sim::Signal(n_pu * kRatedRpm);
  s.signal(sim::Quantity::kTorque) = sim::Signal(tau_pu * kRatedTorqueNm);
  s.signal(sim::Quantity::kUdc) = sim::Signal(565.0);
  return s;
}

/// Section VI: the 3 kW bench — 220 V link, the IPMSM speed-controlled against a DC load machine
/// on the same shaft, measured currents with noise and ADC resolution, a 14-bit encoder.
sim::Scenario bench(double n_pu, double load_pu, double duration_s) {
  sim::Scenario s = sim::paper_scenario();
  s.name = "bench";
  s.duration_s = duration_s;
  s.seed = 2023;
  s.inverter.model = sim::InverterModel::kSwitching;
  s.mechanics.dynamometer = false;
  s.mechanics.inertia_kgm2 = 0.05;
  s.mechanics.friction_Nms = 0.002;
  s.control.speed_control = true;
  s.control.inertia_kgm2 = 0.05;
  s.control.speed_bandwidth_Hz = 5.0;
  s.sensors.current_noise_A = 0.02;
  s.sensors.current_lsb_A = 0.01;
  s.sensors.encoder_counts = 16384;
  s.sensors.speed_window = 16;
  s.signal(sim::Quantity::kSpeed) = sim::Signal(n_pu * kRatedRpm);
  s.signal(sim::Quantity::kTorque) = sim::Signal(load_pu * kRatedTorqueNm);
  s.signal(sim::Quantity::kUdc) = sim::Signal(220.0);
  return s;
}

ReproductionCase make(std::string id, std::string figure, std::string description, core::Param p, CaseKind kind, double n,
                      double tau, double step_s, sim::Scenario s) {
  ReproductionCase c;
  c.id = std::move(id);
  c.figure = std::move(figure);
  c.description = std::move(description);
  c.parameter = p;
  c.kind = kind;
  c.n_pu = n;
  c.tau_pu = tau;
  c.step_time_s = step_s;
  c.scenario = std::move(s);
  c.estimator = c.scenario.machine.estimator;
  c.estimator.regimes.enabled =
      false;  // the paper's estimator as it states it: no sample classified or skipped (regime.hpp)
  return c;
}

/// The hypothesis of the Section VI R_s rows: GNA given SGA's R_s settings (gain sequences and initial
/// Hessian), the only settings under which GNA reaches tab_comparison's 8 s / 4 s. The paper states
/// tab_psimgains' GNA column, with which no initial Hessian gets below the bound of erratum E5
/// (docs/derivations.md); the primary rows keep that column.
void gna_on_sga_r_s_settings(ReproductionCase& c) {
  auto& gains = c.estimator.gains;
  const auto& sga = gains[static_cast<int>(core::Algorithm::kSga)];
  auto& gna = gains[static_cast<int>(core::Algorithm::kGna)];
  gna.hessian[core::kRs] = sga.hessian[core::kRs];
  gna.gain[core::kRs] = sga.gain[core::kRs];
  c.estimator.initial_gna_hessian_pu = c.estimator.initial_sga_hessian_pu[core::kRs] * core::Mat2::Identity();
}

void step_parameter(ReproductionCase& c, double at_s, double scale) {
  const sim::Quantity q = c.parameter == core::Param::kPsiM ? sim::Quantity::kPsiM : sim::Quantity::kRs;
  c.scenario.signal(q).add({at_s, sim::EventKind::kStep, scale * c.scenario.signal(q).initial(), 0.0});
}

PaperFigures figures(std::optional<double> sga_s, std::optional<double> gna_s, std::optional<double> sga_e,
                     std::optional<double> gna_e, std::string words) {
  PaperFigures f;
  f.convergence_time_s = {sga_s, gna_s, std::nullopt};
  f.steady_state_error_pct = {sga_e, gna_e, std::nullopt};
  f.qualitative = std::move(words);
  return f;
}

/// One operating point of a Section V panel: speed and torque [pu].
struct ErtsPanel {
  const char* panel;
  double n, tau;
};

/// Section V, fig_psim_adapt: −8 % step of ψm at t = 2 s (the Hessians have settled by then).
void add_erts_psim_steps(std::vector<ReproductionCase>& cases) {
  const std::string words = "SGA and PhyInt stable and noise-free; GNA converges but over-excited at low load ((a), (b))";
  for (const ErtsPanel op :
       {ErtsPanel{"a", -0.2, 0.0}, ErtsPanel{"b", -0.4, 0.2}, ErtsPanel{"c", 0.4, 0.2}, ErtsPanel{"d", 0.8, 0.4}}) {
    auto c =
        make(std::string("V_psim_") + op.panel, std::string("fig_psim_adapt (") + op.panel + ")", "ERTS, -8 % step of psi_m",
             core::Param::kPsiM, CaseKind::kParameterStep, op.n, op.tau, 2.0, erts(op.n, op.tau, 8.0));
    step_parameter(c, 2.0, 0.92);
    c.paper.qualitative = words;
    cases.push_back(std::move(c));
  }
}

/// Section V, fig_rs_adapt: −8 % step of R_s at t = 4 s. The scheduler's ±10 rpm window would block
/// the ±0.05 pu panels; n_lim,2 is widened to 0.06 pu (60 rpm) for these cases only. Then the paper's
/// remark on it: GNA needed a ~10x smaller gain for R_s. Panel (a) again with GNA on SGA's sequences
/// shows why.
void add_erts_rs_steps(std::vector<ReproductionCase>& cases) {
  const auto rs = core::Param::kRs;
  const std::string words = "GNA needs ~10x smaller gain and is slower; PhyInt noise-free but significantly slower than SGA";
  for (const ErtsPanel op :
       {ErtsPanel{"a", -0.05, 0.2}, ErtsPanel{"b", 0.0, 0.2}, ErtsPanel{"c", 0.0, 0.6}, ErtsPanel{"d", 0.05, 0.6}}) {
    auto c = make(std::string("V_rs_") + op.panel, std::string("fig_rs_adapt (") + op.panel + ")", "ERTS, -8 % step of R_s",
                  rs, CaseKind::kParameterStep, op.n, op.tau, 4.0, erts(op.n, op.tau, 44.0));
    step_parameter(c, 4.0, 0.92);
    c.estimator.r_s_max_speed_rpm = 60.0;
    c.paper.qualitative = words;
    cases.push_back(std::move(c));
  }
  auto c = make("V_rs_a_gna_on_sga_gains", "fig_rs_adapt (a), GNA with SGA's gains",
                "ERTS, -8 % step of R_s; GNA given SGA's gain sequences", rs, CaseKind::kParameterStep, -0.05, 0.2, 4.0,
                erts(-0.05, 0.2, 20.0));
  step_parameter(c, 4.0, 0.92);
  c.estimator.r_s_max_speed_rpm = 60.0;
  c.estimator.gains[static_cast<int>(core::Algorithm::kGna)] = c.estimator.gains[static_cast<int>(core::Algorithm::kSga)];
  c.role = CaseRole::kStudy;
  c.study_figure = "gna_rs_gain_study";
  c.paper.qualitative = "to achieve stable tracking with GNA, gamma_0 needed to be nearly 10 times smaller";
  cases.push_back(std::move(c));
}

/// Section VI, Fig_lab_psim (a), (b): the estimators start at t = 1 s with the offline ψm; the
/// machine's is 8 % lower. Each panel also as a study with SGA's initial Hessian r[0] = 1 instead of the
/// shipped, cautious 100 (docs/reproduction.md, difference 3).
void add_bench_psim_starts(std::vector<ReproductionCase>& cases) {
  struct PsimStart {
    const char* panel;
    double load_pu, paper_sga_s, paper_gna_s, paper_sga_e, paper_gna_e;
    const char* description;
    const char* words;
  };
  for (const PsimStart p :
       {PsimStart{"a", 0.0, 2.0, 0.5, -0.5, 0.5, "bench, no load, 0.3 pu", "GNA slightly quicker with a 6 % overshoot"},
        PsimStart{"b", 0.4, 1.5, 1.5, 0.0, 0.0, "bench, 0.4 pu load, 0.3 pu", "nearly identical adaptation"}}) {
    for (const bool small_r0 : {false, true}) {
      auto c = make(std::string("VI_psim_") + p.panel + (small_r0 ? "_sga_r0_1" : ""),
                    std::string("Fig_lab_psim (") + p.panel + ")" + (small_r0 ? ", SGA from r[0] = 1" : ""), p.description,
                    core::Param::kPsiM, CaseKind::kStartWithError, 0.3, p.load_pu, 1.0, bench(0.3, p.load_pu, 7.0));
      c.scenario.signal(sim::Quantity::kPsiM) = sim::Signal(0.92 * 1.14);
      c.paper = figures(p.paper_sga_s, p.paper_gna_s, p.paper_sga_e, p.paper_gna_e, p.words);
      if (small_r0) {
        c.role = CaseRole::kStudy;
        c.study_figure = "sga_initial_hessian_study";
        c.estimator.initial_sga_hessian_pu = core::Vec2(1.0, 1.0);
      }
      cases.push_back(std::move(c));
    }
  }
}

/// Section VI, Fig_lab_psim (c) speed reversal −0.3 → +0.3 pu at 0.4 pu load; (d) load step −0.4 → +0.4 pu
/// at 0.3 pu.
void add_bench_psim_disturbances(std::vector<ReproductionCase>& cases) {
  const auto psi = core::Param::kPsiM;
  {
    auto c = make("VI_psim_c", "Fig_lab_psim (c)", "bench, speed reversal -0.3 -> +0.3 pu at 0.4 pu load", psi,
                  CaseKind::kDisturbance, -0.3, 0.4, 2.0, bench(-0.3, 0.4, 8.0));
    c.scenario.signal(sim::Quantity::kSpeed).add({2.0, sim::EventKind::kRamp, 0.3 * kRatedRpm, 0.5});
    c.paper = figures(std::nullopt, std::nullopt, std::nullopt, std::nullopt,
                      "psi_m remains stable (SGA); GNA oscillates while the speed is unsettled, then converges");
    cases.push_back(std::move(c));
  }
  auto c = make("VI_psim_d", "Fig_lab_psim (d)", "bench, load step -0.4 -> +0.4 pu at 0.3 pu", psi, CaseKind::kDisturbance,
                0.3, -0.4, 2.0, bench(0.3, -0.4, 8.0));
  c.scenario.signal(sim::Quantity::kTorque).add({2.0, sim::EventKind::kStep, 0.4 * kRatedTorqueNm, 0.0});
  c.paper = figures(std::nullopt, std::nullopt, std::nullopt, std::nullopt,
                    "SGA stable through the sign change of i_q; GNA oscillates while the speed is unsettled");
  cases.push_back(std::move(c));
}

/// Section VI, Fig_Labrs (a), (b): start at t = 1 s with the offline R_s; the machine's is 8 % lower. The
/// paper's settings (tab_psimgains' GNA column); the hypothesis rows give GNA SGA's R_s settings instead.
void add_bench_rs_starts(std::vector<ReproductionCase>& cases) {
  struct RsStart {
    const char* panel;
    double n, paper_sga_s, paper_gna_s;
    const char* description;
    const char* words;
  };
  for (const RsStart r : {RsStart{"a", 0.0, 8.0, 8.0, "bench, standstill, 0.4 pu load", "performance differences marginal"},
                          RsStart{"b", 0.005, 6.0, 4.0, "bench, 0.005 pu, 0.4 pu load",
                                  "performance differences marginal; speed ripple visible on the estimates"}}) {
    for (const bool hypothesis : {false, true}) {
      auto c = make(std::string("VI_rs_") + r.panel + (hypothesis ? "_gna_sga_settings" : ""),
                    std::string("Fig_Labrs (") + r.panel + ")" + (hypothesis ? ", GNA with SGA's R_s settings" : ""),
                    r.description, core::Param::kRs, CaseKind::kStartWithError, r.n, 0.4, 1.0, bench(r.n, 0.4, 41.0));
      c.scenario.signal(sim::Quantity::kRs) = sim::Signal(0.92 * 2.25);
      if (hypothesis) {
        gna_on_sga_r_s_settings(c);
        c.role = CaseRole::kHypothesis;
        c.study_figure = "gna_rs_gain_study";
      }
      c.paper = figures(r.paper_sga_s, r.paper_gna_s, 0.0, 0.0, r.words);
      cases.push_back(std::move(c));
    }
  }
}

/// Section VI, Fig_Labrs (c) speed step 0.001 → 0.005 pu at 0.4 pu load; (d) load step 0.4 → 0.6 pu at
/// standstill.
void add_bench_rs_disturbances(std::vector<ReproductionCase>& cases) {
  const auto rs = core::Param::kRs;
  {
    auto c = make("VI_rs_c", "Fig_Labrs (c)", "bench, speed step 0.001 -> 0.005 pu at 0.4 pu load", rs,
                  CaseKind::kDisturbance, 0.001, 0.4, 3.0, bench(0.001, 0.4, 10.0));
    c.scenario.signal(sim::Quantity::kSpeed).add({3.0, sim::EventKind::kStep, 0.005 * kRatedRpm, 0.0});
    c.paper = figures(std::nullopt, std::nullopt, std::nullopt, std::nullopt,
                      "steady states indistinguishable; SGA more stable through the transient");
    cases.push_back(std::move(c));
  }
  auto c = make("VI_rs_d", "Fig_Labrs (d)", "bench, load step 0.4 -> 0.6 pu at standstill", rs, CaseKind::kDisturbance, 0.0,
                0.4, 3.0, bench(0.0, 0.4, 10.0));
  c.scenario.signal(sim::Quantity::kTorque).add({3.0, sim::EventKind::kStep, 0.6 * kRatedTorqueNm, 0.0});
  c.paper = figures(std::nullopt, std::nullopt, std::nullopt, std::nullopt,
                    "SGA yields more stable tracking during the load (and speed) transient");
  cases.push_back(std::move(c));
}

}  // namespace

std::vector<ReproductionCase> paper_cases() {
  std::vector<ReproductionCase> cases;
  add_erts_psim_steps(cases);
  add_erts_rs_steps(cases);
  add_bench_psim_starts(cases);
  add_bench_psim_disturbances(cases);
  add_bench_rs_starts(cases);
  add_bench_rs_disturbances(cases);
  return cases;
}

double initial_error(const ReproductionCase& c) {
  const bool psi = c.parameter == core::Param::kPsiM;
  const double offline = psi ? c.estimator.initial_psi_m_Wb : c.estimator.initial_r_s_Ohm;
  const double actual = c.scenario.signal(psi ? sim::Quantity::kPsiM : sim::Quantity::kRs).initial();
  return offline / actual - 1.0;
}

StandstillRs standstill_rs_model(const ReproductionCase& c, core::Algorithm a) {
  const core::MachineSi& nominal = c.scenario.machine.machine;
  const core::PerUnitBase base = core::PerUnitBase::from_rated(nominal.rated);
  core::MachineSi machine = nominal;
  machine.r_s_Ohm = c.scenario.signal(sim::Quantity::kRs).initial();
  const core::MachinePu m = core::to_pu(base, machine);
  const double settled = core::mtpa_reference(m, c.tau_pu).squaredNorm() / (m.r_s_pu * m.r_s_pu);  // (i/r_s)²
  const core::GainSequences& g = c.estimator.gains[static_cast<int>(a)];
  const double hessian0 = a == core::Algorithm::kGna ? c.estimator.initial_gna_hessian_pu(core::kRs, core::kRs)
                                                     : c.estimator.initial_sga_hessian_pu[core::kRs];
  return {g.hessian[core::kRs], g.gain[core::kRs], c.estimator.nominal_sample_period_s, hessian0 / settled};
}

const char* to_string(CaseRole r) noexcept {
  switch (r) {
    case CaseRole::kPaper:
      return "paper";
    case CaseRole::kHypothesis:
      return "hypothesis";
    case CaseRole::kStudy:
      return "study";
  }
  return "?";
}

const char* parameter_name(core::Param p) noexcept { return p == core::Param::kPsiM ? "psi_m" : "r_s"; }

}  // namespace rpem::analysis
