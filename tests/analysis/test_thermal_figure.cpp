// `rpem figures --thermal-estimate`: the ±2σ band's coverage of the measured points after the held-out line,
// counted by hand on a constructed estimate, and the measured columns' names drawn as they are written.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "rpem/analysis/thermal/thermal_figure.hpp"
#include "rpem/io/errors.hpp"
#include "support/gnuplot_text.hpp"
#include "support/temp_file.hpp"

namespace rpem::analysis {
namespace {

TEST(ThermalFigure, CoverageCountsTheMeasuredPointsAfterTheLineInsideTheBand) {
  // The estimate: magnet 50 ± 2·1 °C, winding 80 ± 2·2 °C at every second of 0…10 s.
  std::string est =
      "t,T_magnet_rpem,T_winding_rpem,t_magnet_fused_C,t_magnet_fused_sd_C,t_winding_fused_C,t_winding_fused_sd_C\n";
  for (int k = 0; k <= 10; ++k) est += std::to_string(k) + ",49,81,50,1,80,2\n";
  // Measured between the rows (interpolated there); the first point lies before the line at 2 s and is not
  // counted, though it is outside both bands. After it: magnet 51 in, 53 out, 49 in, 47.9 out (2 of 4);
  // winding 77 in, 83 in, 85 out, 80 in (3 of 4).
  const std::string measured =
      "t,T_magnet,T_winding\n"
      "0.5,60,60\n"
      "2.5,51,77\n"
      "4.5,53,83\n"
      "6.5,49,85\n"
      "8.5,47.9,80\n";
  const test::TempFile est_csv("est.csv", est), measured_csv("measured.csv", measured), png("fused.png"), script("fused.gp");
  ThermalFigureInput in;
  in.estimate_csv = est_csv.path();
  in.measured_csv = measured_csv.path();
  in.judged_after_s = 2.0;
  const ThermalFigureCoverage c = write_thermal_figure(png.path(), in);
  EXPECT_DOUBLE_EQ(c.magnet, 0.5);
  EXPECT_DOUBLE_EQ(c.winding, 0.75);
  EXPECT_GT(std::filesystem::file_size(png.path()), 1000U);
  // The names are text: in gnuplot's enhanced mode `T_magnet` would read as T with the subscript m.
  const std::string gp = test::read_file(script.path());
  EXPECT_NE(gp.find("title \"measured (T_magnet)\" noenhanced"), std::string::npos) << gp.substr(gp.rfind("plot"));
  EXPECT_NE(gp.find("title \"measured (T_winding)\" noenhanced"), std::string::npos);
  EXPECT_EQ(test::misprinted_gnuplot_text(gp), std::vector<std::string>{});
}

TEST(ThermalFigure, TimesThatDoNotIncreaseAreRefusedAtTheirLine) {
  // The band is interpolated at each measured time and the curves drawn in order: a time that goes back or is NaN is
  // a data error at its line (exit 65), not a figure of crossed lines. A missing temperature reading (NaN) is not.
  const std::string est =
      "t,T_magnet_rpem,T_winding_rpem,t_magnet_fused_C,t_magnet_fused_sd_C,t_winding_fused_C,t_winding_fused_sd_C\n"
      "0,49,81,50,1,80,2\n1,49,81,50,1,80,2\n2,49,81,50,1,80,2\n";
  const test::TempFile est_csv("est.csv", est), png("fused.png");
  auto refusal = [&](const std::string& measured) -> std::string {
    const test::TempFile measured_csv("measured.csv", measured);
    ThermalFigureInput in;
    in.estimate_csv = est_csv.path();
    in.measured_csv = measured_csv.path();
    try {
      (void)write_thermal_figure(png.path(), in);
    } catch (const io::DataError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(refusal("t,T_magnet,T_winding\n0.5,50,80\n\n0.2,50,80\n").find("measured.csv:4:1: column t: does not increase"),
            std::string::npos);
  EXPECT_NE(refusal("t,T_magnet,T_winding\n0.5,50,80\nnan,50,80\n").find("measured.csv:3:1: column t: NaN"),
            std::string::npos);
  EXPECT_EQ(refusal("t,T_magnet,T_winding\n0.5,50,80\n1.5,nan,80\n"), "");
  // Times on another clock (a thermocouple log from 0 beside an estimate on the drive's): nothing judged, said so.
  EXPECT_NE(refusal("t,T_magnet,T_winding\n43200,50,80\n43201,50,80\n")
                .find("measured.csv:2: column t: its times (43200 to 43201 s) share none with the estimate's (0 to 2 s"),
            std::string::npos)
      << refusal("t,T_magnet,T_winding\n43200,50,80\n43201,50,80\n");
  EXPECT_EQ(refusal("t,T_magnet,T_winding\n1.5,50,80\n3,50,80\n"), "");  // one point within: judged
}

TEST(ThermalFigure, RpemAloneIsDrawnFromItsFirstAdaptationAndSaidWhereItNeverAdapted) {
  // ψm adapts from the row at 4 s on (psi_m_active), R_s never: before 4 s T_magnet_rpem is the law's value at the
  // configured ψm, which nothing observed (the Paderborn log read 102 °C there at a cold start), and T_winding_rpem
  // is the configured R_s's 20 °C throughout (the same log's winding reached 123 °C).
  std::string est =
      "t,psi_m_active,r_s_active,T_magnet_rpem,T_winding_rpem,t_magnet_fused_C,t_magnet_fused_sd_C,t_winding_fused_C,"
      "t_winding_fused_sd_C\n";
  for (int k = 0; k <= 10; ++k)
    est += std::to_string(k) + (k >= 4 ? ",1" : ",0") + ",0," + (k >= 4 ? "60" : "102") + ",20,55,1,80,2\n";
  const test::TempFile est_csv("est.csv", est), png("alone.png"), script("alone.gp");
  ThermalFigureInput in;
  in.estimate_csv = est_csv.path();
  (void)write_thermal_figure(png.path(), in);
  ASSERT_GT(std::filesystem::file_size(png.path()), 1000U);
  const std::string gp = test::read_file(script.path());
  // The magnet's block: column 5 (RPEM alone) nan before 4 s, 60 from it; no 102 drawn anywhere. Searched as a
  // cell (after a space), not as digits: the script names its files after the process id, which may hold "102".
  EXPECT_EQ(gp.find(" 102\n"), std::string::npos) << gp;
  EXPECT_EQ(gp.find(" 102 "), std::string::npos) << gp;
  EXPECT_NE(gp.find("\n3 55 53 57 nan\n"), std::string::npos) << gp;
  EXPECT_NE(gp.find("\n4 55 53 57 60\n"), std::string::npos) << gp;
  EXPECT_NE(gp.find("RPEM alone (from ψm's first adaptation, held)"), std::string::npos);
  // The winding: no RPEM-alone curve, and the panel says why.
  EXPECT_NE(gp.find("winding (RPEM alone: R_s never adapted in this log)"), std::string::npos);
  EXPECT_EQ(gp.find("$winding_est u 1:5"), std::string::npos);
  EXPECT_EQ(test::misprinted_gnuplot_text(gp), std::vector<std::string>{});
}

}  // namespace
}  // namespace rpem::analysis
