// The midpoint hash map against std::map under random inserts and erases (backward-shift deletion
// must keep every remaining key reachable).
#include <gtest/gtest.h>

#include <map>
#include <random>
#include <utility>

#include "strata/hierarchy/edge_midpoint_map.hpp"

namespace strata {
namespace {

TEST(EdgeMidpointMap, AgreesWithStdMap) {
  EdgeMidpointMap map;
  std::map<std::pair<int, int>, int> reference;
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> vertex(0, 60);  // few vertices: long probe runs, collisions
  for (int step = 0; step < 20000; ++step) {
    int a = vertex(rng), b = vertex(rng);
    if (a == b) continue;
    const std::pair<int, int> key = std::minmax(a, b);
    if (rng() % 3 == 0) {
      EXPECT_EQ(map.erase(b, a), reference.erase(key) == 1);
    } else if (reference.count(key) == 0) {
      map.insert(a, b, step);
      reference[key] = step;
    }
    if (step % 500 == 0) {
      ASSERT_EQ(map.size(), reference.size());
      for (int u = 0; u <= 60; ++u)
        for (int v = u + 1; v <= 60; ++v) {
          const auto found = reference.find({u, v});
          ASSERT_EQ(map.find(v, u), found == reference.end() ? -1 : found->second);
        }
    }
  }
  EXPECT_LE(2 * map.size(), map.capacity());
  EXPECT_THROW(map.insert(3, 3, 0), std::logic_error);
}

TEST(EdgeMidpointMap, InsertingTwiceIsAnError) {
  EdgeMidpointMap map;
  EXPECT_EQ(map.find(1, 2), -1);
  EXPECT_FALSE(map.erase(1, 2));
  map.insert(2, 1, 7);
  EXPECT_EQ(map.find(1, 2), 7);
  EXPECT_THROW(map.insert(1, 2, 8), std::logic_error);
}

}  // namespace
}  // namespace strata
