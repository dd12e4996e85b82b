#include "trajroi/eval/points_csv.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace trajroi::eval {
namespace {

TEST(PointsCsv, ParsesThreeOrFourFieldsCommentsAndNonFinite) {
  const auto points = parse_points_csv("# x,y,z,i\n1,2,3\n4.5, -6 ,7,99\n\nnan,0,0\n", "p.csv");
  ASSERT_EQ(points.size(), 3u);
  EXPECT_EQ(points[1].x, 4.5);
  EXPECT_EQ(points[1].y, -6.0);
  EXPECT_TRUE(std::isnan(points[2].x));
}

TEST(PointsCsv, ErrorsNameFileAndLine) {
  for (const char* text : {"1,2,3\n1,2\n", "1,2,3\n1,2,3,4,5\n", "1,2,3\na,b,c\n", "1,2,3\n1,,3\n"}) {
    try {
      (void)parse_points_csv(text, "p.csv");
      FAIL() << "accepted " << text;
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("p.csv:2:", 0), 0u) << e.what();
    }
  }
}

}  // namespace
}  // namespace trajroi::eval
