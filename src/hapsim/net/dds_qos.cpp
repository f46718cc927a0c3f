#include "hapsim/net/dds_qos.h"

#include <new>

namespace hapsim::net {

namespace {

constexpr int kCommandHistory = 16;

}  // namespace

Qos::Qos() : qos_(dds_create_qos()) {
  if (qos_ == nullptr) {
    throw std::bad_alloc();
  }
}

Qos::~Qos() {
  dds_delete_qos(qos_);
}

void apply_profile(Qos& qos, QosProfile profile) {
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST,
                   profile == QosProfile::kCommand ? kCommandHistory : 1);
  if (profile == QosProfile::kStream) {
    dds_qset_reliability(qos.get(), DDS_RELIABILITY_BEST_EFFORT, 0);
    dds_qset_durability(qos.get(), DDS_DURABILITY_VOLATILE);
  } else {
    dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(qos.get(), DDS_DURABILITY_TRANSIENT_LOCAL);
  }
}

}  // namespace hapsim::net
