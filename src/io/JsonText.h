#pragma once

#include <istream>
#include <string>

#include <nlohmann/json.hpp>

namespace subscan {

/// JSON text parsed, a file's or a string's. Throws subscan::Error "not valid JSON (byte N)"
/// for text that is not JSON, and for a number beyond a double's range (`1e400`), which the
/// parser reports as an error of another kind; and "the key 'K' appears twice in one object",
/// where the parser would keep the last.
nlohmann::json parseJsonText(std::istream& stream);
nlohmann::json parseJsonText(const std::string& text);

}  // namespace subscan
