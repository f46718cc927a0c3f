// Local models at 1 kHz over real Cyclone DDS on loopback: a child process publishes, this one
// takes without blocking the stream (a waitset only wakes it, as a non-haptic thread may), and
// every sample is checked bit for bit, in order, through the device's gate. Loss and latency are
// printed, never asserted (the machine is shared and virtual).
#include "hapsim/core/statistics.h"
#include "hapsim/net/local_model_gate.h"
#include "hapsim/net/topic_reader.h"
#include "hapsim/net/topic_writer.h"

#include "net/net_test_support.h"

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

using Clock = std::chrono::steady_clock;
using test::message_for;

constexpr dds_domainid_t kDomain = 71;
constexpr std::uint64_t kCount = 2000;  // two seconds at 1 kHz

// The samples after the stream, each wrong in one way, told apart by their sim_time_s.
struct BadSample {
  hapsim_msg_LocalModel message;
  SampleVerdict expected;
};

std::vector<BadSample> bad_samples() {
  std::vector<BadSample> bad;
  hapsim_msg_LocalModel m = message_for(kCount + 2);
  m.f0_n[0] = std::numeric_limits<double>::quiet_NaN();
  bad.push_back({m, SampleVerdict::kMalformed});
  m = message_for(kCount + 3);
  m.scene_hash ^= 0xff;
  bad.push_back({m, SampleVerdict::kOtherScene});
  m = message_for(kCount / 2);  // an old sequence arriving late
  bad.push_back({m, SampleVerdict::kOutOfOrder});
  m = message_for(kCount + 4);
  // Answers a device state older than the gate allows: older than every good one (they answer
  // states 2 to kCount + 1; 0 would be the simulation's own script, which has no age).
  m.device_sequence = 1;
  bad.push_back({m, SampleVerdict::kStale});
  m = message_for(kCount + 5);
  m.f0_n[2] = 1e7;
  bad.push_back({m, SampleVerdict::kOutOfRange});
  for (std::size_t i = 0; i < bad.size(); ++i) {
    bad[i].message.sim_time_s = 1000.0 + static_cast<double>(i);
  }
  return bad;
}

// The child: waits for the reader, streams kCount models on absolute 1 ms deadlines, then the
// bad ones. Exits without returning into gtest.
[[noreturn]] void publish_and_exit() {
  int code = 0;
  try {
    Participant participant(kDomain, "loopback");
    TopicWriter<hapsim_msg_LocalModel> writer(participant);
    const auto give_up = Clock::now() + std::chrono::seconds(20);
    while (writer.matched_readers() == 0 && Clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    // The reader matches this writer a moment after; best-effort sends nothing to a reader
    // that has not.
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    auto deadline = Clock::now();
    for (std::uint64_t s = 2; s <= kCount + 1; ++s) {
      writer.write(message_for(s));
      deadline += std::chrono::milliseconds(1);
      std::this_thread::sleep_until(deadline);
    }
    for (const BadSample& b : bad_samples()) {
      writer.write(b.message);
      deadline += std::chrono::milliseconds(5);
      std::this_thread::sleep_until(deadline);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // let the last ones leave
  } catch (const std::exception& e) {
    std::fprintf(stderr, "publisher: %s\n", e.what());
    code = 1;
  }
  _exit(code);
}

TEST(DdsLoopback, LocalModelsAtOneKilohertzArriveBitForBitInOrderAndBadOnesAreCounted) {
  ASSERT_TRUE(test::on_loopback_config());
  // Fork before this process makes any DDS entity (ctest runs each test in its own process).
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    publish_and_exit();
  }

  Participant participant(kDomain, "loopback");
  TopicReader<hapsim_msg_LocalModel> reader(participant);
  const dds_entity_t waitset = dds_create_waitset(participant.participant());
  ASSERT_GT(waitset, 0);
  const dds_entity_t readable = dds_create_readcondition(reader.handle(), DDS_ANY_STATE);
  ASSERT_EQ(dds_waitset_attach(waitset, readable, 0), DDS_RETCODE_OK);

  LocalModelLimits limits;
  limits.max_age_cycles = kCount;
  LocalModelGate gate(test::kDeviceId, test::kSceneHash, 1, limits);
  const std::uint64_t device_sequence_now = kCount + 2;
  std::map<double, SampleVerdict> expected_bad;
  for (const BadSample& b : bad_samples()) {
    expected_bad[b.message.sim_time_s] = b.expected;
  }

  std::uint64_t good = 0;
  std::uint64_t bit_mismatches = 0;
  std::uint64_t last_accepted = 0;
  std::uint64_t bad_seen = 0;
  std::uint64_t bad_verdict_wrong = 0;
  std::vector<double> latency_us;
  latency_us.reserve(kCount);
  int status = 0;
  bool child_done = false;
  const auto give_up = Clock::now() + std::chrono::seconds(40);
  while (Clock::now() < give_up) {
    dds_waitset_wait(waitset, nullptr, 0, DDS_MSECS(50));
    reader.take([&](const hapsim_msg_LocalModel& m, const dds_sample_info_t& info) {
      latency_us.push_back(static_cast<double>(dds_time() - info.source_timestamp) * 1e-3);
      LocalContactModel model;
      const SampleVerdict verdict = gate.admit(m, device_sequence_now, model);
      const auto bad = expected_bad.find(m.sim_time_s);
      if (bad != expected_bad.end()) {
        ++bad_seen;
        bad_verdict_wrong += verdict != bad->second ? 1 : 0;
        return;
      }
      ++good;
      EXPECT_EQ(verdict, SampleVerdict::kAccepted) << "sequence " << m.model_sequence;
      bit_mismatches += test::same_bits(m, message_for(m.model_sequence)) ? 0 : 1;
      EXPECT_GT(m.model_sequence, last_accepted);
      last_accepted = m.model_sequence;
    });
    if (!child_done && waitpid(child, &status, WNOHANG) == child) {
      child_done = true;
    } else if (child_done) {
      break;  // one more pass after the publisher left
    }
  }
  dds_delete(waitset);
  if (!child_done) {
    kill(child, SIGKILL);
    waitpid(child, &status, 0);
  }
  ASSERT_TRUE(child_done) << "publisher did not finish";
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "publisher failed";

  const double loss = 1.0 - static_cast<double>(good) / static_cast<double>(kCount);
  const SampleSummary latency = summarize_samples(latency_us);
  std::printf(
      "loopback 1 kHz: %llu/%llu local models (loss %.2f %%), bad samples seen %llu/5; "
      "write->take latency p50 %.0f us, p99 %.0f us, max %.0f us\n",
      static_cast<unsigned long long>(good), static_cast<unsigned long long>(kCount), loss * 100.0,
      static_cast<unsigned long long>(bad_seen), latency.p50, latency.p99, latency.max);
  EXPECT_EQ(bit_mismatches, 0u);
  EXPECT_EQ(bad_verdict_wrong, 0u);
  EXPECT_EQ(gate.count(SampleVerdict::kAccepted), good);
  EXPECT_EQ(gate.rejected(), bad_seen);
  // Best-effort may drop a few; a stream that mostly did not arrive is a broken setup.
  EXPECT_GT(good, kCount / 2);
}

}  // namespace
}  // namespace hapsim::net
