// The connected viewer's session (`hapsim view --connect`): it shows the served scene's device
// rating (omega.3: 12 N), not a default 10 N. A simulation host is played by this test: it
// publishes the SceneInfo that `hapsim serve` would, on the shipped loopback config.
#include "hapsim/ui/net_viewer_session.h"

#include "hapsim/core/text_file.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/scene_hash.h"
#include "hapsim/net/scene_info.h"
#include "hapsim/net/topic_writer.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/world/world.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdlib>
#include <string>

namespace hapsim {
namespace {

TEST(NetViewerSession, ShowsTheServedDevicesRating) {
  // Never the machine's real interface: the shipped loopback config, read by Cyclone when the
  // first participant joins (so this test and the session share one domain).
  const std::string config =
      std::string("file://") + HAPSIM_SOURCE_DIR + "/config/cyclonedds-loopback.xml";
  ::setenv("CYCLONEDDS_URI", config.c_str(), 0);

  const std::string scene_file = std::string(HAPSIM_SOURCE_DIR) + "/scenes/csg_block.json";
  const RunSetup setup = make_run_setup(load_scene(scene_file), DeviceChoice::external());
  ASSERT_EQ(setup.profile->name, "omega3");
  ASSERT_DOUBLE_EQ(setup.profile->max_force_n, 12.0);

  net::SceneInfoSample info;
  info.scene_hash = net::scene_hash(setup.world->content_hash());
  info.serve_id = net::draw_serve_id();
  info.tool_count = 1;
  info.scene_file = scene_file;
  info.scene_json = read_text_file(scene_file, net::kMaxSceneJsonBytes, "scene");
  const std::string session = "netviewer" + std::to_string(::getpid());
  net::Participant host(net::kDefaultDomain, session);
  net::TopicWriter<hapsim_msg_SceneInfo> info_out(host);
  ASSERT_TRUE(info_out.write(net::scene_info_message(info)));

  ViewerConfig viewer;
  viewer.connect = true;
  viewer.session = session;
  viewer.connect_timeout_s = 60.0;
  const auto connected = make_net_viewer_session(viewer);
  EXPECT_DOUBLE_EQ(connected->readout().rated_force_n, 12.0);
  // The bars' full scale: the rating within what the scene's materials can push (6 N).
  EXPECT_DOUBLE_EQ(connected->readout().bar_full_scale_n, 6.0);
}

}  // namespace
}  // namespace hapsim
