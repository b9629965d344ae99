#include "io/JsonText.h"

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

namespace {

template <class Input>
nlohmann::json parsed(Input& input) {
    try {
        return nlohmann::json::parse(input);
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
