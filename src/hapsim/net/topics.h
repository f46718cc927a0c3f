// Which C type travels on which topic with which QoS (net/idl/hapsim_messages.idl).
#pragma once

#include "hapsim/net/dds_entity.h"
#include "hapsim/net/dds_qos.h"
#include "hapsim/net/participant.h"
#include "hapsim_messages.h"

#include <string>

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

template <>
struct TopicTraits<hapsim_msg_SceneInfo> {
  static const dds_topic_descriptor_t& descriptor() { return hapsim_msg_SceneInfo_desc; }
  static constexpr const char* kName = "hapsim_scene_info";
  static constexpr QosProfile kQos = QosProfile::kState;
};

template <>
struct TopicTraits<hapsim_msg_ViewState> {
  static const dds_topic_descriptor_t& descriptor() { return hapsim_msg_ViewState_desc; }
  static constexpr const char* kName = "hapsim_view_state";
  static constexpr QosProfile kQos = QosProfile::kStream;
};

template <>
struct TopicTraits<hapsim_msg_Command> {
  static const dds_topic_descriptor_t& descriptor() { return hapsim_msg_Command_desc; }
  static constexpr const char* kName = "hapsim_command";
  static constexpr QosProfile kQos = QosProfile::kCommand;
};

template <>
struct TopicTraits<hapsim_msg_CommandReply> {
  static const dds_topic_descriptor_t& descriptor() { return hapsim_msg_CommandReply_desc; }
  static constexpr const char* kName = "hapsim_command_reply";
  static constexpr QosProfile kQos = QosProfile::kCommand;
};

/// The topic of message type T in `participant`'s domain with `qos` (a reader's and a writer's
/// QoS must match the topic's). Throws hapsim::Error naming the topic when Cyclone refuses.
template <typename T>
[[nodiscard]] DdsEntity create_topic(const Participant& participant, const Qos& qos) {
  return DdsEntity(
      check_dds(dds_create_topic(participant.participant(), &TopicTraits<T>::descriptor(),
                                 TopicTraits<T>::kName, qos.get(), nullptr),
                std::string("creating topic ") + TopicTraits<T>::kName));
}

/// A reader of T's topic in `participant`'s session with the topic's QoS; `topic` receives the
/// topic entity (the reader's owner keeps it). Throws hapsim::Error naming the topic.
template <typename T>
[[nodiscard]] DdsEntity create_reader(const Participant& participant, DdsEntity& topic) {
  Qos qos;
  apply_profile(qos, TopicTraits<T>::kQos);
  topic = create_topic<T>(participant, qos);
  return DdsEntity(
      check_dds(dds_create_reader(participant.subscriber(), topic.get(), qos.get(), nullptr),
                std::string("creating a reader on ") + TopicTraits<T>::kName));
}

}  // namespace hapsim::net
