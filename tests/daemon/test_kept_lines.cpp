// The MQTT publisher's outage buffer: first in, first out across growth and wrap-around, and
// at the limit the oldest line goes.
#include <gtest/gtest.h>

#include "daemon/kept_lines.hpp"

using gyrod::daemon::KeptLines;

TEST(KeptLines, KeepsOrderWhileGrowingAndWrapping) {
  KeptLines<int> kept(1000);
  int next_in = 0, next_out = 0;
  for (int round = 0; round < 50; ++round) {  // in 30, out 20: it grows while it wraps
    for (int i = 0; i < 30; ++i) {
      EXPECT_TRUE(kept.pushBack(next_in++));
    }
    for (int i = 0; i < 20; ++i) {
      ASSERT_EQ(kept.front(), next_out++);
      kept.popFront();
    }
  }
  EXPECT_EQ(kept.size(), 500u);
  while (!kept.empty()) {
    ASSERT_EQ(kept.front(), next_out++);
    kept.popFront();
  }
  EXPECT_EQ(next_out, next_in);
}

TEST(KeptLines, DropsTheOldestAtTheLimit) {
  KeptLines<int> kept(100);
  int dropped = 0;
  for (int i = 0; i < 250; ++i) dropped += kept.pushBack(i) ? 0 : 1;
  EXPECT_EQ(dropped, 150);
  EXPECT_EQ(kept.size(), 100u);
  for (int expected = 150; expected < 250; ++expected) {
    ASSERT_EQ(kept.front(), expected);
    kept.popFront();
  }
  KeptLines<int> none(0);
  EXPECT_FALSE(none.pushBack(1));
  EXPECT_TRUE(none.empty());
}
