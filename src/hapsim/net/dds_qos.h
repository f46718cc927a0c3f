// The two QoS profiles hapsim uses (STACK.md, issue 12):
//  * streams (device state, local models at 1 kHz): best-effort, keep-last-1, volatile — a late
//    sample is worth nothing, a resent one even less; taken without blocking in the loop;
//  * state (scene description): reliable, keep-last-1, transient-local — a viewer that joins late
//    still gets the current scene;
//  * commands (pause, reset, a material's contact): reliable, transient-local, keep-last-16 per
//    issuer — a pause followed at once by a reset must not lose the pause to keep-last-1.
#pragma once

#include <dds/dds.h>

namespace hapsim::net {

/// An owned dds_qos_t.
class Qos {
 public:
  Qos();
  Qos(const Qos&) = delete;
  Qos& operator=(const Qos&) = delete;
  ~Qos();
  [[nodiscard]] dds_qos_t* get() const noexcept { return qos_; }

 private:
  dds_qos_t* qos_;
};

enum class QosProfile { kStream, kState, kCommand };

/// Sets `profile`'s reliability, history and durability on `qos`.
void apply_profile(Qos& qos, QosProfile profile);

}  // namespace hapsim::net
