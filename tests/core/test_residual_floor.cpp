// The rounding-floor check used by the solvers' and flows' monotone-residual tests.
#include "../residual_floor.h"

#include <gtest/gtest.h>

#include <vector>

namespace {

using mcf::testing::falls_above_rounding_floor;
using mcf::testing::kRelativeResidualFloor;

TEST(ResidualFloor, ARiseAboveTheFloorFails) {
  EXPECT_FALSE(falls_above_rounding_floor(std::vector<double>{1e-1, 1e-3, 2e-3, 1e-5}));
  EXPECT_FALSE(falls_above_rounding_floor(std::vector<double>{1e-1, 1e-1}));  // a stall
}

TEST(ResidualFloor, NoiseAtTheFloorPasses) {
  // The values seen on one processor: the last cycle "raises" a residual of 2.4e-16.
  EXPECT_TRUE(falls_above_rounding_floor(
      std::vector<double>{1e-2, 1e-6, 1e-10, 1e-14, 2.43466e-16, 2.44002e-16}));
  EXPECT_GT(kRelativeResidualFloor, 1e-13);
  EXPECT_LT(kRelativeResidualFloor, 1e-11);
}

}  // namespace
