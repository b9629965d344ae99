#include "io/JsonText.h"

#include <optional>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

namespace {

template <class Input>
nlohmann::json parsed(Input& input) {
    // A key given twice in one object: the parser keeps the last without a word, so a
    // settings file could say two things and mean one.
    std::vector<std::set<std::string>> keysOfOpenObjects;
    std::optional<std::string> repeated;
    auto noteKeys = [&](int, nlohmann::json::parse_event_t event, nlohmann::json& value) {
        using Event = nlohmann::json::parse_event_t;
        if (event == Event::object_start) {
            keysOfOpenObjects.emplace_back();
        } else if (event == Event::object_end && !keysOfOpenObjects.empty()) {
            keysOfOpenObjects.pop_back();
        } else if (event == Event::key && !keysOfOpenObjects.empty() && !repeated &&
                   !keysOfOpenObjects.back().insert(value.get<std::string>()).second) {
            repeated = value.get<std::string>();
        }
        return true;
    };
    try {
        nlohmann::json json = nlohmann::json::parse(input, noteKeys);
        if (repeated) {
            throw Error(fmt::format("the key '{}' appears twice in one object", *repeated));
        }
        return json;
    } catch (const nlohmann::json::parse_error& error) {
        throw Error(fmt::format("not valid JSON (byte {})", error.byte));
    } catch (const nlohmann::json::out_of_range&) {
        throw Error("not valid JSON: a number beyond a double's range");
    }
}

}  // namespace

nlohmann::json parseJsonText(std::istream& stream) {
    return parsed(stream);
}

nlohmann::json parseJsonText(const std::string& text) {
    return parsed(text);
}

}  // namespace subscan
