// Cdr(sample): the bytes a serialized subscription hands over for `sample` (its type's own CDR,
// encapsulation included), for tests that feed serialized callbacks or decoders.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <dyad/msg/types.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/rtps/common/SerializedPayload.h>

namespace dyad::testing {

template <class T>
std::vector<uint8_t> Cdr(T& sample) {
  std::unique_ptr<eprosima::fastdds::dds::TopicDataType> support(TypeInfoOf<T>().make_type_support());
  eprosima::fastrtps::rtps::SerializedPayload_t payload(support->getSerializedSizeProvider(&sample)());
  if (!support->serialize(&sample, &payload)) return {};
  return std::vector<uint8_t>(payload.data, payload.data + payload.length);
}

}  // namespace dyad::testing
