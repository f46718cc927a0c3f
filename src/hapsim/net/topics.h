// Which C type travels on which topic with which QoS (net/idl/hapsim_messages.idl).
#pragma once

#include "hapsim/net/dds_qos.h"
#include "hapsim_messages.h"

namespace hapsim::net {

template <typename T>
struct TopicTraits;

template <>
struct TopicTraits<hapsim_msg_LocalModel> {
  static const dds_topic_descriptor_t& descriptor() { return hapsim_msg_LocalModel_desc; }
  static constexpr const char* kName = "hapsim_local_model";
  static constexpr QosProfile kQos = QosProfile::kStream;
};

template <>
struct TopicTraits<hapsim_msg_DeviceState> {
  static const dds_topic_descriptor_t& descriptor() { return hapsim_msg_DeviceState_desc; }
  static constexpr const char* kName = "hapsim_device_state";
  static constexpr QosProfile kQos = QosProfile::kStream;
};

}  // namespace hapsim::net
