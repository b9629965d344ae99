#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include <fmt/format.h>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "core/Error.h"

namespace subscan {

/// Throws subscan::Error naming the first key of `json` that is not in `known`: a typo such as
/// "metod" would otherwise be ignored and leave the default in force without a word.
inline void rejectUnknownKeys(const nlohmann::json& json, std::string_view section,
                              std::initializer_list<std::string_view> known) {
    if (!json.is_object()) {
        throw Error(fmt::format("the settings section '{}' must be a JSON object", section));
    }
    for (const auto& [key, value] : json.items()) {
        if (std::find(known.begin(), known.end(), key) != known.end()) {
            continue;
        }
        std::string expected;
        for (const std::string_view name : known) {
            expected += expected.empty() ? "" : ", ";
            expected += name;
        }
        throw Error(fmt::format("unknown setting '{}' in '{}' (expected one of: {})", key, section,
                                expected));
    }
}

/// Reads `key` into `value` when present (absent keys keep their defaults, so a settings file
/// holds only what it changes), checking min <= value <= max. Throws subscan::Error naming the
/// key. The number is checked before it becomes a T: -1 would wrap around to 2^64 - 1 in an
/// unsigned setting, and 2.5 lose its half in an integer one.
template <class T>
void readSetting(const nlohmann::json& json, std::string_view key, T& value, T min, T max) {
    const auto found = json.find(key);
    if (found == json.end()) {
        return;
    }
    if (!found->is_number()) {
        throw Error(fmt::format("the setting '{}' has the wrong type", key));
    }
    const double read = found->get<double>();
    if (std::is_integral_v<T> && read != std::floor(read)) {
        throw Error(fmt::format("the setting '{}' = {} is not a whole number", key, read));
    }
    // Floats compare as floats: 0.01 in the file is the bound 0.01f, not below it (and a
    // double beyond a float's range is not cast to one at all).
    const bool inside =
        std::is_integral_v<T>
            ? read >= static_cast<double>(min) && read <= static_cast<double>(max)
            : std::abs(read) <= static_cast<double>(std::numeric_limits<T>::max()) &&
                  static_cast<T>(read) >= min && static_cast<T>(read) <= max;
    if (!inside) {
        throw Error(fmt::format("the setting '{}' = {} is outside {}..{}", key, read, min, max));
    }
    value = static_cast<T>(read);
}

inline void readSetting(const nlohmann::json& json, std::string_view key, bool& value) {
    const auto found = json.find(key);
    if (found == json.end()) {
        return;
    }
    if (!found->is_boolean()) {
        throw Error(fmt::format("the setting '{}' must be true or false", key));
    }
    value = found->get<bool>();
}

/// An RGB triple, each component within min..max.
inline void readSetting(const nlohmann::json& json, std::string_view key, glm::vec3& value,
                        float min, float max) {
    const auto found = json.find(key);
    if (found == json.end()) {
        return;
    }
    std::array<float, 3> read{};
    try {
        read = found->get<std::array<float, 3>>();
    } catch (const nlohmann::json::exception&) {
        throw Error(fmt::format("the setting '{}' must be 3 numbers", key));
    }
    for (const float component : read) {
        if (!(component >= min && component <= max)) {
            throw Error(fmt::format("the setting '{}' has a value outside {}..{}", key, min, max));
        }
    }
    value = {read[0], read[1], read[2]};
}

/// Enum <-> name tables: {value, "name"} pairs, the names as the CLI and JSON spell them.
template <class Enum, std::size_t N>
std::string nameOf(const std::pair<Enum, std::string_view> (&table)[N], Enum value) {
    for (const auto& [candidate, name] : table) {
        if (candidate == value) {
            return std::string(name);
        }
    }
    return "?";
}

/// Throws subscan::Error listing the allowed names.
template <class Enum, std::size_t N>
Enum parseName(const std::pair<Enum, std::string_view> (&table)[N], std::string_view text,
               std::string_view what) {
    std::string allowed;
    for (const auto& [value, name] : table) {
        if (name == text) {
            return value;
        }
        allowed += allowed.empty() ? "" : ", ";
        allowed += name;
    }
    throw Error(fmt::format("'{}' is not a {} (expected one of: {})", text, what, allowed));
}

template <class Enum, std::size_t N>
void readEnum(const nlohmann::json& json, std::string_view key, Enum& value,
              const std::pair<Enum, std::string_view> (&table)[N], std::string_view what) {
    if (const auto found = json.find(key); found != json.end()) {
        if (!found->is_string()) {
            throw Error(fmt::format("the setting '{}' must be a string", key));
        }
        value = parseName(table, found->get<std::string>(), what);
    }
}

inline nlohmann::json toJson(const glm::vec3& value) {
    return {value.x, value.y, value.z};
}

}  // namespace subscan
