// The distance behind "did you mean" (misspelt TOML keys, unknown gyroctl commands).
#include <gtest/gtest.h>

#include "formats/edit_distance.hpp"

using gyrod::formats::editDistance;

TEST(EditDistance, CountsInsertionsDeletionsAndSubstitutions) {
  EXPECT_EQ(editDistance("kitten", "sitting"), 3u);  // two substitutions and an insertion
  EXPECT_EQ(editDistance("rat_hz", "rate_hz"), 1u);
  EXPECT_EQ(editDistance("anlyze", "analyze"), 1u);
  EXPECT_EQ(editDistance("abc", "abc"), 0u);
}

TEST(EditDistance, AgainstTheEmptyStringIsTheLengthAndItIsSymmetric) {
  EXPECT_EQ(editDistance("", "status"), 6u);
  EXPECT_EQ(editDistance("status", ""), 6u);
  EXPECT_EQ(editDistance("flter", "filter"), editDistance("filter", "flter"));
  EXPECT_EQ(editDistance("watch", "allan"), editDistance("allan", "watch"));
}
