// `hapsim serve` as its own process on loopback: its local models arrive, pass the device's gate
// (but for the teleports where a host takes over or lets go) and follow the scene's script; a
// device host's states take over the world while they keep coming (and the models answer them), bad
// states are counted by reason, and the script takes over again when the host goes silent.
#include "hapsim/net/device_state_codec.h"
#include "hapsim/net/local_model_gate.h"
#include "hapsim/net/scene_hash.h"
#include "hapsim/net/topic_reader.h"
#include "hapsim/net/topic_writer.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include "apps/hapsim_process.h"
#include "net/net_test_support.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <regex>
#include <thread>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

using Clock = std::chrono::steady_clock;

constexpr dds_domainid_t kDomain = 74;
const std::string kScene = std::string(HAPSIM_SOURCE_DIR) + "/scenes/knee_procedural.json";

std::uint64_t knee_hash() {
  RunSetup setup = make_run_setup(load_scene(kScene), DeviceChoice::scene_script());
  return scene_hash(setup.world->content_hash());
}

TEST(ServeProcess, PublishesGatedModelsFollowsADeviceHostAndCountsBadStates) {
  ASSERT_TRUE(test::on_loopback_config());
  const std::uint64_t hash = knee_hash();
  hapsim::test::RunResult served;
  std::thread server([&] {
    served = hapsim::test::run_hapsim("serve " + kScene +
                                      " --duration 6 --session serve-test --domain " +
                                      std::to_string(kDomain));
  });

  Participant participant(kDomain, "serve-test");
  TopicReader<hapsim_msg_LocalModel> models(participant);
  TopicWriter<hapsim_msg_DeviceState> states(participant);
  const auto give_up = Clock::now() + std::chrono::seconds(15);
  while ((models.matched_writers() == 0 || states.matched_readers() == 0) &&
         Clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_GT(models.matched_writers(), 0u) << "serve never published";

  LocalModelLimits limits;
  limits.max_age_cycles = std::numeric_limits<std::uint64_t>::max();
  LocalModelGate gate(0, hash, 1, limits);
  std::uint64_t sent_sequence = 0;
  std::uint64_t scripted = 0;
  std::uint64_t scripted_touching = 0;
  std::uint64_t answered = 0;
  std::uint64_t answered_wrong = 0;
  const auto drain = [&] {
    models.take([&](const hapsim_msg_LocalModel& m, const dds_sample_info_t&) {
      LocalContactModel model;
      const SampleVerdict verdict = gate.admit(m, sent_sequence, model);
      if (verdict != SampleVerdict::kAccepted) {
        // The step where the host's pose replaces the script's (and back) is a 1 m teleport; the
        // world forgets the tools' motion there, so no model carries a ~1000 m/s v0.
        const double speed_m_per_s = Vec3(m.v0_m_per_s[0], m.v0_m_per_s[1], m.v0_m_per_s[2]).norm();
        ADD_FAILURE() << "model refused (" << static_cast<int>(verdict) << "), v0 " << speed_m_per_s
                      << " m/s";
        return;
      }
      if (model.device_sequence == 0) {
        ++scripted;
        scripted_touching += model.f0_world_n.norm() > 0.0 ? 1 : 0;
      } else {
        // Answers our far-away device: no force, our pose, one of our states.
        ++answered;
        const bool right = model.f0_world_n == Vec3::Zero() &&
                           (model.x0_world_m - Vec3(0.0, 0.0, 1.0)).norm() < 0.1 &&
                           model.device_sequence <= sent_sequence;
        answered_wrong += right ? 0 : 1;
        if (!right && answered_wrong <= 3) {
          ADD_FAILURE() << "wrong answer: model " << model.sequence << " for state "
                        << model.device_sequence << " (sent " << sent_sequence << "), x0 "
                        << model.x0_world_m.transpose() << ", f0 " << model.f0_world_n.transpose()
                        << ", sim time " << model.sim_time_s;
        }
      }
    });
  };

  // The scene's script drives for two seconds (the palpation touches the knee from 0.9 s).
  for (auto until = Clock::now() + std::chrono::milliseconds(2000); Clock::now() < until;) {
    drain();
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  // A device host for a second, 1 m above the knee, with three malformed and three
  // other-scene states among its own (each followed by a pause, so keep-last-1 keeps it).
  DeviceStateSample state;
  state.input.p_world = Vec3(0.0, 0.0, 1.0);
  for (int k = 0; k < 1000; ++k) {
    state.sequence = ++sent_sequence;
    hapsim_msg_DeviceState m = encode_device_state(state, hash);
    if (k % 300 == 150) {
      m.p_m[1] = std::numeric_limits<double>::quiet_NaN();
    } else if (k % 300 == 250) {
      m.scene_hash ^= 1u;
    }
    states.write(m);
    const bool bad = k % 300 == 150 || k % 300 == 250;
    std::this_thread::sleep_for(std::chrono::milliseconds(bad ? 20 : 1));
    drain();
  }
  // Silent again: the script takes over.
  for (auto until = Clock::now() + std::chrono::milliseconds(500); Clock::now() < until;) {
    drain();
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  server.join();

  std::printf("serve test: %llu scripted models (%llu touching), %llu answering the host\n%s",
              static_cast<unsigned long long>(scripted),
              static_cast<unsigned long long>(scripted_touching),
              static_cast<unsigned long long>(answered), served.output.c_str());
  EXPECT_EQ(served.exit_code, 0);
  EXPECT_EQ(gate.rejected(), 0u);  // not even at the two teleports
  EXPECT_GT(scripted_touching, 0u);
  EXPECT_GT(answered, 0u);
  EXPECT_EQ(answered_wrong, 0u);
  EXPECT_NE(served.output.find("device host  joined"), std::string::npos);
  EXPECT_NE(served.output.find("device host  silent"), std::string::npos);
  EXPECT_TRUE(std::regex_search(served.output, std::regex("malformed [1-3],")));
  EXPECT_TRUE(std::regex_search(served.output, std::regex("other scene [1-3],")));
  EXPECT_TRUE(std::regex_search(served.output, std::regex("out of range 0,")));
}

}  // namespace
}  // namespace hapsim::net
