// Several users in one world, across processes (issue 32 item 3): `hapsim serve` with a scene
// whose tools name two device hosts, the trainee's and the instructor's, each a `hapsim device
// --name`. Each host renders its own tool's local models; the trainee's fingertip, pressing 3 mm
// into the FEM block, finds the surface sunk under the instructor's probe 12 mm away (measured
// idle: 1.28 N alone, 0.04 N beside the probe), so the trainee feels the other's dent; a second
// host claiming the trainee's name is refused with one line and exit 2, and serve says so; a name
// the scene does not have is one line too. The world's own test (World.TwoUsersEachPlace...)
// checks each user's force against eq. 1 with the other's dent in both directions.
#include "apps/hapsim_process.h"
#include "net/net_test_support.h"

#include <nlohmann/json.hpp>

#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

using namespace std::chrono_literals;
using hapsim::test::BackgroundHapsim;

const std::string kData = std::string(HAPSIM_SOURCE_DIR) + "/tests/data/two_users/";
const std::string kScene = kData + "fem_block_two_users.json";
const std::string kInstructorScript = kData + "fem_block_instructor.json";

nlohmann::json read_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// A served run of the trainee's press (5 s from its first state), with the instructor's host
// holding its probe beside it when `with_instructor`; the JSON of serve and of each host.
struct Served {
  nlohmann::json serve, trainee, instructor;
  std::string serve_output, second_trainee_output, stranger_output;
  int second_trainee_exit = -1;
  int stranger_exit = -1;
};

Served serve_two_users(const std::string& session, bool with_instructor) {
  Served out;
  const std::string net = " --session " + session + " --domain 88";
  const auto path = [&](const std::string& name) {
    return hapsim::test::temp_path(session + "_" + name);
  };
  std::optional<BackgroundHapsim> instructor;
  if (with_instructor) {
    // Started first: it waits for serve, presses within 1 s and holds for 20 s.
    instructor.emplace("device --name instructor --scene " + kInstructorScript +
                           " --duration 14 --json " + path("instructor.json").string() + net,
                       path("instructor.log"));
  }
  BackgroundHapsim serve("serve " + kScene + " --wait-for-device --duration 5 --json " +
                             path("serve.json").string() + net,
                         path("serve.log"));
  EXPECT_TRUE(serve.wait_for("waiting", 30s)) << serve.output();
  BackgroundHapsim trainee(
      "device --name trainee --duration 6.5 --json " + path("trainee.json").string() + net,
      path("trainee.log"));
  if (with_instructor) {
    EXPECT_TRUE(serve.wait_for("device host 'trainee' joined", 30s)) << serve.output();
    // A second host claims the trainee's name while the first drives; a third names no user.
    BackgroundHapsim second("device --name trainee --duration 4" + net, path("second.log"));
    BackgroundHapsim stranger("device --name nobody --duration 4" + net, path("stranger.log"));
    out.second_trainee_exit = second.wait();
    out.second_trainee_output = second.output();
    out.stranger_exit = stranger.wait();
    out.stranger_output = stranger.output();
  }
  EXPECT_EQ(serve.wait(), 0) << serve.output();
  EXPECT_EQ(trainee.wait(), 0) << trainee.output();
  out.serve_output = serve.output();
  out.serve = read_json(path("serve.json"));
  out.trainee = read_json(path("trainee.json"));
  if (instructor) {
    instructor->signal(SIGINT);  // its script holds on; the session is over
    (void)instructor->wait();
    out.instructor = read_json(path("instructor.json"));
  }
  return out;
}

TEST(TwoUsersProcess, EachHostFeelsItsOwnToolAndTheTraineeFeelsTheInstructorsDent) {
  ASSERT_TRUE(test::on_loopback_config());
  const Served alone = serve_two_users("two-users-alone", false);
  const Served both = serve_two_users("two-users-both", true);

  // Alone: the trainee presses the block; the instructor's probe is absent (no force, no contact).
  const double alone_n = alone.trainee["peak_force_n"].get<double>();
  EXPECT_GT(alone_n, 0.5);
  EXPECT_EQ(alone.serve["tools"][1]["contact_steps"].get<int>(), 0);
  EXPECT_EQ(alone.serve["serve"]["device_hosts"][1]["cycles_driven"].get<int>(), 0);

  // Together: both hosts drove the world and rendered their own tool's models.
  const nlohmann::json& hosts = both.serve["serve"]["device_hosts"];
  ASSERT_EQ(hosts.size(), 2u) << both.serve.dump(2);
  EXPECT_EQ(hosts[0]["name"], "trainee");
  EXPECT_EQ(hosts[1]["name"], "instructor");
  EXPECT_EQ(hosts[1]["device_id"].get<int>(), 1);
  EXPECT_GT(hosts[0]["cycles_driven"].get<int>(), 3'000);
  EXPECT_GT(hosts[1]["cycles_driven"].get<int>(), 3'000);
  EXPECT_EQ(both.trainee["name"], "trainee");
  EXPECT_EQ(both.instructor["name"], "instructor");
  EXPECT_EQ(both.instructor["device_id"].get<int>(), 1);
  EXPECT_GT(both.instructor["models_rendered"].get<int>(), 3'000);
  // The instructor felt its probe pressing 12 mm deep (about 6 N idle), as the world had it.
  const double instructor_n = both.instructor["peak_force_n"].get<double>();
  const double probe_n = both.serve["tools"][1]["peak_force_n"].get<double>();
  EXPECT_GT(instructor_n, 2.0);
  EXPECT_GT(instructor_n, 0.6 * probe_n);
  EXPECT_LT(instructor_n, 1.6 * probe_n);
  // The trainee's fingertip, on the same press, meets the surface the probe pulled down.
  EXPECT_LT(both.trainee["peak_force_n"].get<double>(), 0.5 * alone_n)
      << "alone " << alone_n << " N";
  EXPECT_EQ(both.serve["pop_throughs"].get<int>(), 0);

  // The second trainee: refused by serve (the first host keeps the name) and told so.
  EXPECT_EQ(both.second_trainee_exit, 2) << both.second_trainee_output;
  EXPECT_NE(both.second_trainee_output.find("device host 'trainee' (device id 0) is taken"),
            std::string::npos)
      << both.second_trainee_output;
  EXPECT_GT(hosts[0]["second_host_states_refused"].get<int>(), 0);
  EXPECT_NE(both.serve_output.find("claimed by a second host"), std::string::npos)
      << both.serve_output;
  EXPECT_EQ(both.trainee["models_for_another_host"].get<int>(), 0);
  // A name the scene does not have: one line naming the ones it has.
  EXPECT_EQ(both.stranger_exit, 2) << both.stranger_output;
  EXPECT_NE(both.stranger_output.find("has device hosts 'trainee', 'instructor', not this one"),
            std::string::npos)
      << both.stranger_output;
}

}  // namespace
}  // namespace hapsim::net
