// A session is a DDS partition: two sessions on one domain never see each other's samples.
#include "hapsim/core/error.h"
#include "hapsim/net/topic_reader.h"
#include "hapsim/net/topic_writer.h"

#include "net/net_test_support.h"

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

using Clock = std::chrono::steady_clock;

constexpr dds_domainid_t kDomain = 72;

TEST(SessionPartition, NamesMapToTheirOwnPartitionAndWildcardsAreRefused) {
  EXPECT_EQ(session_partition("trainee-1"), "hapsim.trainee-1");
  EXPECT_THROW((void)session_partition(""), Error);
  EXPECT_THROW((void)session_partition("*"), Error);  // would match every session
  EXPECT_THROW((void)session_partition("a?"), Error);
  EXPECT_THROW((void)session_partition("a.b"), Error);
  EXPECT_THROW((void)session_partition(std::string(65, 'a')), Error);
}

TEST(Session, TwoSessionsOnOneDomainNeverSeeEachOther) {
  ASSERT_TRUE(test::on_loopback_config());
  Participant alice(kDomain, "alice");
  Participant bob(kDomain, "bob");
  TopicWriter<hapsim_msg_LocalModel> alice_writer(alice);
  TopicWriter<hapsim_msg_LocalModel> bob_writer(bob);
  TopicReader<hapsim_msg_LocalModel> alice_reader(alice);
  TopicReader<hapsim_msg_LocalModel> bob_reader(bob);

  // Each reader matches its own session's writer, and only that one.
  const auto give_up = Clock::now() + std::chrono::seconds(10);
  while ((alice_reader.matched_writers() < 1 || bob_reader.matched_writers() < 1) &&
         Clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(alice_reader.matched_writers(), 1u);
  EXPECT_EQ(bob_reader.matched_writers(), 1u);

  int alice_got = 0;
  int bob_got = 0;
  int crossed = 0;
  for (std::uint64_t s = 1; s <= 50; ++s) {
    hapsim_msg_LocalModel a = test::message_for(s);
    a.device_id = 1;
    hapsim_msg_LocalModel b = test::message_for(s);
    b.device_id = 2;
    alice_writer.write(a);
    bob_writer.write(b);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    alice_reader.take([&](const hapsim_msg_LocalModel& m, const dds_sample_info_t&) {
      (m.device_id == 1 ? alice_got : crossed) += 1;
    });
    bob_reader.take([&](const hapsim_msg_LocalModel& m, const dds_sample_info_t&) {
      (m.device_id == 2 ? bob_got : crossed) += 1;
    });
  }
  EXPECT_GT(alice_got, 0);
  EXPECT_GT(bob_got, 0);
  EXPECT_EQ(crossed, 0);
}

}  // namespace
}  // namespace hapsim::net
