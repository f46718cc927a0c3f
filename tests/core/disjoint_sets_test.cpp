#include "hapsim/core/disjoint_sets.h"

#include <gtest/gtest.h>

namespace hapsim {
namespace {

TEST(DisjointSets, JoinsThroughChainsAndKeepsApartWhatWasNeverJoined) {
  DisjointSets s(7);
  s.unite(0, 1);
  s.unite(2, 1);
  s.unite(4, 5);
  s.unite(5, 6);
  EXPECT_EQ(s.find(0), s.find(2));
  EXPECT_EQ(s.find(4), s.find(6));
  EXPECT_NE(s.find(0), s.find(4));
  EXPECT_EQ(s.find(3), 3u);  // alone
  s.unite(6, 2);
  EXPECT_EQ(s.find(0), s.find(4));
  EXPECT_NE(s.find(3), s.find(0));
}

}  // namespace
}  // namespace hapsim
