// `hapsim bench network --dds`: the distributed palpation over real Cyclone DDS on loopback, as
// separate processes of `hapsim` (serve --wait-for-device, device, and N `watch` viewers),
// once with no viewer and once with N: the device's round trip (a state to the first model
// answering it), how its 1 kHz loop kept time, serve's loop, and the views each viewer got.
// With --secure: the probe's round trip and a participant's join time, plain against secure.
#pragma once

#include <string>

namespace hapsim::app {

struct NetworkDdsArgs {
  std::string scene = "scenes/knee_procedural.json";
  int viewers = 8;
  double duration_s = 10.5;
  int domain = 0;
  std::string json_path;
  /// Only the probe, plain and then with DDS Security (keys made for it): the round trip and
  /// the time a new participant takes to join (discovery, handshake, the scene), each way.
  bool secure_compare = false;
};

void run_network_dds(const NetworkDdsArgs& args);

}  // namespace hapsim::app
