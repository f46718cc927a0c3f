// The lock-free hand-over buffers under two real threads: a triple buffer never shows a torn
// snapshot and never goes back in time; a ring delivers every accepted item once, in order.
#include "hapsim/core/triple_buffer.h"
#include "hapsim/core/spsc_ring.h"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <thread>

namespace hapsim {
namespace {

// A snapshot big enough to span several cache lines: every word holds the sequence number, so a
// reader that sees two different numbers inside one snapshot saw a torn write.
struct Snapshot {
  std::array<std::uint64_t, 64> words{};
};

TEST(TripleBuffer, ReaderSeesNoTornOrStaleSnapshotUnderStress) {
  TripleBuffer<Snapshot> buffer(Snapshot{});
  constexpr std::uint64_t kPublishes = 300'000;
  std::atomic<bool> done{false};
  std::atomic<bool> go{false};
  std::thread writer([&] {
    while (!go.load()) {
      // start together with the reader, so the two really overlap
    }
    for (std::uint64_t seq = 1; seq <= kPublishes; ++seq) {
      Snapshot& s = buffer.write_slot();
      for (auto& w : s.words) {
        w = seq;
      }
      buffer.publish();
    }
    done.store(true);
  });
  std::uint64_t last_seen = 0;
  std::uint64_t torn = 0;
  std::uint64_t backwards = 0;
  std::uint64_t updates = 0;
  go.store(true);
  for (;;) {
    const bool finished = done.load();  // read before update(): the last publish is not missed
    if (!buffer.update()) {
      if (finished) {
        break;
      }
      continue;
    }
    ++updates;
    const Snapshot& s = buffer.read_slot();
    const std::uint64_t seq = s.words[0];
    for (const auto w : s.words) {
      torn += w != seq ? 1 : 0;
    }
    backwards += seq <= last_seen ? 1 : 0;
    last_seen = seq;
  }
  writer.join();
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(backwards, 0u);  // every update() gives a strictly newer snapshot
  EXPECT_GT(updates, 0u);
  // After the writer is done the reader ends on the very last snapshot.
  EXPECT_EQ(buffer.read_slot().words[0], kPublishes);
  EXPECT_EQ(buffer.read_slot().words[63], kPublishes);
}

TEST(TripleBuffer, UpdateIsFalseUntilSomethingNewIsPublished) {
  TripleBuffer<int> buffer(7);
  EXPECT_FALSE(buffer.update());
  EXPECT_EQ(buffer.read_slot(), 7);
  buffer.write_slot() = 8;
  buffer.publish();
  buffer.write_slot() = 9;
  buffer.publish();
  EXPECT_TRUE(buffer.update());
  EXPECT_EQ(buffer.read_slot(), 9);  // the newest, not the oldest unseen
  EXPECT_FALSE(buffer.update());
  EXPECT_EQ(buffer.read_slot(), 9);
}

TEST(TripleBuffer, WriterSlotIsNeverTheReadersSlot) {
  TripleBuffer<int> buffer(0);
  for (int i = 1; i < 50; ++i) {
    buffer.write_slot() = i;
    EXPECT_NE(&buffer.write_slot(), &buffer.read_slot());
    buffer.publish();
    if (i % 3 == 0) {
      ASSERT_TRUE(buffer.update());
      EXPECT_EQ(buffer.read_slot(), i);
    }
    EXPECT_NE(&buffer.write_slot(), &buffer.read_slot());
  }
}

TEST(SpscRing, DeliversEveryAcceptedItemOnceInOrder) {
  SpscRing<std::uint64_t> ring(1000);
  EXPECT_EQ(ring.capacity(), 1024u);
  constexpr std::uint64_t kItems = 500'000;
  std::atomic<std::uint64_t> accepted{0};
  std::atomic<bool> done{false};
  std::thread producer([&] {
    for (std::uint64_t i = 1; i <= kItems; ++i) {
      if (ring.push(i)) {
        accepted.fetch_add(1);
      }
    }
    done.store(true);
  });
  std::uint64_t received = 0;
  std::uint64_t last = 0;
  std::uint64_t out_of_order = 0;
  for (;;) {
    const bool finished = done.load();
    while (const std::uint64_t* item = ring.front()) {
      out_of_order += *item <= last ? 1 : 0;
      last = *item;
      ring.pop();
      ++received;
    }
    if (finished) {
      break;
    }
  }
  producer.join();
  EXPECT_EQ(out_of_order, 0u);
  EXPECT_EQ(received, accepted.load());
  EXPECT_GT(received, 0u);
}

TEST(SpscRing, RefusesWhenFullInsteadOfOverwriting) {
  SpscRing<int> ring(4);
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(ring.push(i));
  }
  EXPECT_FALSE(ring.push(99));
  ASSERT_NE(ring.front(), nullptr);
  EXPECT_EQ(*ring.front(), 0);
  ring.pop();
  EXPECT_TRUE(ring.push(4));
  for (int expected = 1; expected <= 4; ++expected) {
    ASSERT_NE(ring.front(), nullptr);
    EXPECT_EQ(*ring.front(), expected);
    ring.pop();
  }
  EXPECT_EQ(ring.front(), nullptr);
}

}  // namespace
}  // namespace hapsim
