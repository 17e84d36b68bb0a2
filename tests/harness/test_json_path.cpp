#include "harness/json_path.h"

#include <gtest/gtest.h>

namespace mcf {
namespace {

using nlohmann::json;

TEST(JsonPath, ReadsAndWritesDottedPaths) {
  json j{{"solver", {{"cycles", 2}}}, {"mesh", "m"}};
  ASSERT_NE(json_at_path(j, "solver.cycles"), nullptr);
  EXPECT_EQ(*json_at_path(j, "solver.cycles"), 2);
  EXPECT_EQ(*json_at_path(j, "mesh"), "m");
  EXPECT_EQ(json_at_path(j, "solver.smooth"), nullptr);
  EXPECT_EQ(json_at_path(j, "mesh.name"), nullptr);  // through a value that is no object
  set_json_path(j, "octree.depth", 7);
  set_json_path(j, "solver.cycles", 3);
  EXPECT_EQ(j, (json{{"solver", {{"cycles", 3}}}, {"mesh", "m"}, {"octree", {{"depth", 7}}}}));
}

}  // namespace
}  // namespace mcf
