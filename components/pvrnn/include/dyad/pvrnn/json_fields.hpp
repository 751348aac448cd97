// dyad/pvrnn/json_fields.hpp: exact reads of the whole-number fields in the JSON headers of
// model and observer files (checked_file).
//
// nlohmann's get<int>() converts whatever number it finds: a float out of range (1e30) is
// undefined behaviour and an integer out of range (4294967302) silently wraps. JsonInt<T> instead
// accepts only a JSON integer that T can hold, else throws std::out_of_range naming the key and
// the value ("d = 1e+30: not a whole number in -2147483648..2147483647"); the file readers turn
// that into a DataLoss Status naming the file. Header-only.
#pragma once

#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace dyad::pvrnn {

// `value` itself; `key` names it in the message.
template <typename T>
T JsonIntValue(const nlohmann::json& value, const std::string& key) {
  using L = std::numeric_limits<T>;
  bool fits = false;
  if (value.is_number_unsigned()) {
    fits = value.get<uint64_t>() <= static_cast<uint64_t>(L::max());
  } else if (value.is_number_integer()) {
    const int64_t v = value.get<int64_t>();
    fits = L::is_signed ? (v >= static_cast<int64_t>(L::min()) && (L::digits >= 63 || v <= static_cast<int64_t>(L::max())))
                        : v >= 0;
  }
  if (!fits)
    throw std::out_of_range(key + " = " + value.dump() + ": not a whole number in " + std::to_string(L::min()) + ".." +
                            std::to_string(L::max()));
  return value.is_number_unsigned() ? static_cast<T>(value.get<uint64_t>()) : static_cast<T>(value.get<int64_t>());
}

// `parent[key]` (std::out_of_range if missing).
template <typename T>
T JsonInt(const nlohmann::json& parent, const char* key) {
  return JsonIntValue<T>(parent.at(key), key);
}

// A JSON array of whole numbers.
template <typename T>
std::vector<T> JsonIntArray(const nlohmann::json& parent, const char* key) {
  const nlohmann::json& array = parent.at(key);
  if (!array.is_array()) throw std::out_of_range(std::string(key) + ": not an array");
  std::vector<T> out;
  for (size_t i = 0; i < array.size(); ++i) out.push_back(JsonIntValue<T>(array[i], std::string(key) + "[" + std::to_string(i) + "]"));
  return out;
}

}  // namespace dyad::pvrnn
