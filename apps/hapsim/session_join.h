// What a command that joins a served session to look at it does first (watch, control): the DDS
// domain (the shipped loopback config unless told otherwise), a participant in the session's
// partition, readers of the scene and of the view states, and the simulation host's SceneInfo —
// or one line and exit 2 when no host answers in time.
#pragma once

#include "commands.h"
#include "dds_options.h"
#include "stop_signal.h"

#include "hapsim/net/dds_domain.h"
#include "hapsim/net/loaned_reader.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/served_scene.h"

#include <atomic>
#include <string>

namespace hapsim::app {

class SessionJoin {
 public:
  /// Waits up to `wait_s` (or until SIGINT/SIGTERM) for the session's simulation host.
  SessionJoin(const DdsOptions& dds, double wait_s)
      : domain_(dds.domain, HAPSIM_DEFAULT_DDS_CONFIG, dds.network()),
        participant_(dds.domain, dds.session),
        info_in_(participant_),
        views_in_(participant_),
        stop_(install_stop_signals()) {
    std::optional<net::SceneInfoSample> info = net::wait_for_scene_info(info_in_, wait_s, &stop_);
    if (!info) {
      throw CommandError("no simulation host (hapsim serve … --session " + dds.session +
                         ") answered within " + std::to_string(wait_s) + " s");
    }
    info_ = std::move(*info);
  }

  [[nodiscard]] const net::DdsDomain& domain() const { return domain_; }
  [[nodiscard]] const net::Participant& participant() const { return participant_; }
  [[nodiscard]] net::LoanedReader<hapsim_msg_ViewState>& views() { return views_in_; }
  /// What the host serves (its scene, hash and start).
  [[nodiscard]] const net::SceneInfoSample& info() const { return info_; }
  /// Set by SIGINT or SIGTERM.
  [[nodiscard]] const std::atomic<bool>& stop() const { return stop_; }

 private:
  net::DdsDomain domain_;
  net::Participant participant_;
  net::LoanedReader<hapsim_msg_SceneInfo> info_in_;
  net::LoanedReader<hapsim_msg_ViewState> views_in_;
  const std::atomic<bool>& stop_;
  net::SceneInfoSample info_;
};

}  // namespace hapsim::app
