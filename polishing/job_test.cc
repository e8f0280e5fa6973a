#include "polishing/job.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/testing/testing.h"

namespace arcwheel::polishing {
namespace {

std::string ErrorOf(const std::string& text) {
  arcwheel::testing::TempDir dir;
  std::ofstream(dir / "map.csv") << text;
  try {
    (void)ReadErrorMapCsv(dir / "map.csv");
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    return e.what();
  }
  return "accepted";
}

TEST(ReadErrorMapCsv, PlacesScatteredRowsOnTheirGridAndLeavesGapsWithoutData) {
  arcwheel::testing::TempDir dir;
  std::ofstream(dir / "map.csv")
      << "# comment\nx_mm,y_mm,error_um\n2.5,-1,0.25\n-2.5,-1,1\n0,1,nan\n2.5,1,-3\n";
  const ErrorMap map = ReadErrorMapCsv(dir / "map.csv");
  EXPECT_EQ(map.nx, 3);
  EXPECT_EQ(map.ny, 2);
  EXPECT_DOUBLE_EQ(map.x0_mm, -2.5);
  EXPECT_DOUBLE_EQ(map.dx_mm, 2.5);
  EXPECT_DOUBLE_EQ(map.dy_mm, 2.0);
  EXPECT_DOUBLE_EQ(map.At(0, 0), 1.0);
  EXPECT_TRUE(std::isnan(map.At(1, 0)));  // never given
  EXPECT_DOUBLE_EQ(map.At(2, 0), 0.25);
  EXPECT_TRUE(std::isnan(map.At(1, 1)));  // given as nan
  EXPECT_DOUBLE_EQ(map.At(2, 1), -3.0);
}

TEST(ReadErrorMapCsv, NamesTheFileAndLineOfMalformedInput) {
  EXPECT_NE(ErrorOf("x,y,z\n").find("map.csv' line 1: header 'x,y,z'"), std::string::npos);
  EXPECT_NE(ErrorOf("x_mm,y_mm,error_um\n0,0,1\n1,0,abc\n").find("line 3: 'abc' is not a number"),
            std::string::npos);
  EXPECT_NE(ErrorOf("x_mm,y_mm,error_um\n0,0,1\n1,0\n").find("line 3: has 2 values"), std::string::npos);
  EXPECT_NE(ErrorOf("x_mm,y_mm,error_um\n0,0,1\n1,0,2\n2,0,2\n3,0,2\n3.4,0,3\n")
                .find("line 6: (3.4, 0) mm is not on the regular grid"),
            std::string::npos);
  EXPECT_NE(ErrorOf("x_mm,y_mm,error_um\n0,0,1\n1,0,2\n1,0,3\n").find("line 4: (1, 0) mm appears twice"),
            std::string::npos);
}

}  // namespace
}  // namespace arcwheel::polishing
