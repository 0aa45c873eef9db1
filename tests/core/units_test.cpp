#include "granmem/core/units.hpp"

#include <gtest/gtest.h>

#include "granmem/core/error.hpp"

namespace granmem {
namespace {

TEST(Units, QuantityWithAndWithoutUnit) {
  EXPECT_DOUBLE_EQ(parse_quantity("0.5 cm", "x").value, 0.5);
  EXPECT_EQ(parse_quantity("0.5 cm", "x").unit, "cm");
  EXPECT_EQ(parse_quantity("25us", "x").unit, "us");
  EXPECT_DOUBLE_EQ(parse_quantity("+12", "x").value, 12);
  EXPECT_EQ(parse_quantity("12", "x").unit, "");
  EXPECT_DOUBLE_EQ(parse_quantity(" 4e6 g/s^2", "x").value, 4e6);
  EXPECT_THROW(parse_quantity("cm", "x"), Error);
  EXPECT_THROW(parse_quantity("", "x"), Error);
}

TEST(Units, ListTakesTheLastUnitForAll) {
  const auto v = parse_quantity_list("0.05,0.05,0.075mm", "--voxel-size");
  ASSERT_EQ(v.size(), 3u);
  for (const auto& q : v)
    EXPECT_EQ(q.unit, "mm");
  EXPECT_DOUBLE_EQ(v[2].value, 0.075);
  EXPECT_THROW(parse_quantity_list("1mm,2cm", "x"), Error);
}

TEST(Units, LengthConversions) {
  EXPECT_DOUBLE_EQ(convert_length(1.5, "cm", "mm"), 15.0);
  EXPECT_DOUBLE_EQ(convert_length(15.0, "mm", "m"), 0.015);
  EXPECT_DOUBLE_EQ(convert_length(2.0, "m", "um"), 2e6);
  EXPECT_TRUE(is_length_unit("voxel"));
  EXPECT_FALSE(is_physical_length_unit("voxel"));
  EXPECT_THROW(metres_per("voxel"), Error);
  EXPECT_THROW(metres_per("inch"), Error);
}

TEST(Units, PressuresInSi) {
  EXPECT_DOUBLE_EQ(parse_si("436Pa", Dimension::pressure, "", "p"), 436);
  EXPECT_DOUBLE_EQ(parse_si("0.436 kPa", Dimension::pressure, "", "p"), 436);
  EXPECT_DOUBLE_EQ(parse_si("4360dyn/cm^2", Dimension::pressure, "", "p"), 436);
  EXPECT_THROW(parse_si("436", Dimension::pressure, "", "p"), Error);     // needs a unit
  EXPECT_THROW(parse_si("436 kg", Dimension::pressure, "", "p"), Error);  // not a pressure
  // Zero needs no unit ("--lid-pressure 0: no lid", as its help says); zero with a wrong
  // unit is still wrong.
  EXPECT_EQ(parse_si("0", Dimension::pressure, "", "p"), 0.0);
  EXPECT_EQ(parse_si("0.0", Dimension::length, "", "d"), 0.0);
  EXPECT_THROW(parse_si("0 kg", Dimension::pressure, "", "p"), Error);
  EXPECT_THROW(parse_si("1e-300", Dimension::pressure, "", "p"), Error);
}

}  // namespace
}  // namespace granmem
