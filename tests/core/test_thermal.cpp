// The drift law every layer shares (core/thermal.hpp) against hand-worked values.
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/core/thermal.hpp"

namespace rpem::core {
namespace {

TEST(DriftLaw, ValueAndTemperatureAreInverses) {
  const DriftLaw copper{0.00393, 20.0, 2.25};
  EXPECT_DOUBLE_EQ(copper.at(20.0), 2.25);
  EXPECT_DOUBLE_EQ(copper.at(70.0), 2.25 * (1.0 + 0.00393 * 50.0));  // 2.692125 Ω
  EXPECT_NEAR(copper.temperature_C(2.692125), 70.0, 1e-12);
  const DriftLaw magnet{-0.0012, 25.0, 1.14};
  EXPECT_NEAR(magnet.temperature_C(1.14 * 0.92), 25.0 + 0.08 / 0.0012, 1e-12);  // −8 % at −0.12 %/K: +66.7 K
}

TEST(DriftLaw, ReferredToAnotherTemperatureIsTheSameLine) {
  const DriftLaw a{0.004, 20.0, 2.0};
  const DriftLaw b = a.referred_to(80.0);
  EXPECT_DOUBLE_EQ(b.reference_C, 80.0);
  EXPECT_DOUBLE_EQ(b.value_ref, 2.0 * 1.24);
  EXPECT_DOUBLE_EQ(b.coeff_per_K, 0.004 / 1.24);
  for (double t : {-20.0, 20.0, 55.0, 140.0}) EXPECT_NEAR(b.at(t), a.at(t), 1e-12) << t;
}

// eq. 14.11a: σ is the larger of the uniform spread and half the distance to the range's farther end.
TEST(Materials, TwoSigmaAboutTheTypicalValueHoldsTheWholeRange) {
  // NdFeB: typical −0.12 %/K in [−0.13, −0.08]: the far end is 0.04 %/K away, σ = 0.02/0.12 (the uniform
  // spread 0.05/√12 = 0.0144 %/K, 12.0 %, would leave −0.08 at 2.8σ).
  EXPECT_NEAR(kNdFeB.rel_sigma(), 0.02 / 0.12, 1e-12);
  // Copper, SmCo, ferrite: the typical value is the range's centre, σ the uniform spread.
  EXPECT_NEAR(kCopper.rel_sigma(), 0.30 / std::sqrt(12.0), 1e-12);
  EXPECT_NEAR(kSmCo.rel_sigma(), 0.0002 / std::sqrt(12.0) / 0.0004, 1e-12);
  EXPECT_NEAR(kFerrite.rel_sigma(), 0.0004 / std::sqrt(12.0) / 0.002, 1e-12);
  for (const MaterialCoefficient& m : {kNdFeB, kSmCo, kFerrite, kCopper}) {
    const double two_sigma = 2.0 * m.rel_sigma() * std::abs(m.typical_per_K);
    EXPECT_LE(m.typical_per_K - two_sigma, m.min_per_K + 1e-15) << m.material;
    EXPECT_GE(m.typical_per_K + two_sigma, m.max_per_K - 1e-15) << m.material;
  }
}

TEST(Materials, RangesHoldTheirTypicalValuesAndTellMagnetsApart) {
  for (const MaterialCoefficient& m : kMagnetMaterials) EXPECT_TRUE(m.contains(m.typical_per_K)) << m.material;
  EXPECT_TRUE(kCopper.contains(kCopper.typical_per_K));
  EXPECT_EQ(material_of(kMagnetMaterials, -0.001)->material, "NdFeB");
  EXPECT_EQ(material_of(kMagnetMaterials, -0.0004)->material, "SmCo");
  EXPECT_EQ(material_of(kMagnetMaterials, -0.002)->material, "ferrite");
  EXPECT_FALSE(material_of(kMagnetMaterials, -0.0052).has_value());  // five times NdFeB: no magnet
  EXPECT_FALSE(material_of(kWindingMaterials, 0.0096).has_value());  // 2.4 × copper
  EXPECT_FALSE(material_of(kWindingMaterials, -0.0096).has_value());
  EXPECT_TRUE(material_of(kWindingMaterials, 0.0041).has_value());
}

}  // namespace
}  // namespace rpem::core
