#include "app/viewer/ViewerScript.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <string_view>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "io/JsonText.h"

namespace subscan::viewer {

namespace {

constexpr std::string_view kActionNames =
    "orbit, pan, zoom, pick, reset, frame, sensor, color, resize, screenshot, mode, panel, "
    "light, settings, exit";
// Beyond this a window is a typo, not a request (and larger than any GPU's texture limit).
constexpr int kMaxWindowSide = 16384;

/// Reads the arguments of one action; errors name the argument.
class ActionReader {
  public:
    explicit ActionReader(const nlohmann::json& json) : json_(json) {}

    /// Refuses keys other than "frame", "action" and `allowed`.
    void allowOnly(std::initializer_list<std::string_view> allowed) const {
        for (const auto& [key, value] : json_.items()) {
            if (key == "frame" || key == "action" ||
                std::find(allowed.begin(), allowed.end(), key) != allowed.end()) {
                continue;
            }
            throw Error(fmt::format("unknown argument '{}'", key));
        }
    }

    std::optional<double> optionalNumber(std::string_view key) const {
        const auto found = json_.find(key);
        if (found == json_.end()) {
            return std::nullopt;
        }
        if (!found->is_number() || !std::isfinite(found->get<double>())) {
            throw Error(fmt::format("'{}' must be a number", key));
        }
        return found->get<double>();
    }

    double number(std::string_view key) const {
        const std::optional<double> value = optionalNumber(key);
        if (!value) {
            throw Error(fmt::format("'{}' is missing", key));
        }
        return *value;
    }

    int integer(std::string_view key, int min, int max) const {
        const auto found = json_.find(key);
        if (found == json_.end()) {
            throw Error(fmt::format("'{}' is missing", key));
        }
        if (!found->is_number_integer() || found->get<long long>() < min ||
            found->get<long long>() > max) {
            throw Error(fmt::format("'{}' must be a whole number in {}..{}", key, min, max));
        }
        return found->get<int>();
    }

    std::string text(std::string_view key) const {
        const auto found = json_.find(key);
        if (found == json_.end()) {
            throw Error(fmt::format("'{}' is missing", key));
        }
        if (!found->is_string() || found->get<std::string>().empty()) {
            throw Error(fmt::format("'{}' must be a non-empty string", key));
        }
        return found->get<std::string>();
    }

    bool boolean(std::string_view key) const {
        const auto found = json_.find(key);
        if (found == json_.end() || !found->is_boolean()) {
            throw Error(fmt::format("'{}' must be true or false", key));
        }
        return found->get<bool>();
    }

    const nlohmann::json& object(std::string_view key) const {
        const auto found = json_.find(key);
        if (found == json_.end() || !found->is_object()) {
            throw Error(fmt::format(
                "'{}' must be an object in the settings file's form, like {{\"scattering\": "
                "{{\"method\": \"single\"}}}}",
                key));
        }
        return *found;
    }

    /// The cursor position "x", "y": both or neither.
    std::optional<glm::dvec2> position() const {
        const std::optional<double> x = optionalNumber("x");
        const std::optional<double> y = optionalNumber("y");
        if (x.has_value() != y.has_value()) {
            throw Error("'x' and 'y' go together");
        }
        if (!x) {
            return std::nullopt;
        }
        return glm::dvec2(*x, *y);
    }

  private:
    const nlohmann::json& json_;
};

ScriptCommand parseCommand(const std::string& name, const ActionReader& reader) {
    if (name == "orbit" || name == "pan" || name == "light") {
        reader.allowOnly({"dx", "dy"});
        const double dx = reader.optionalNumber("dx").value_or(0.0);
        const double dy = reader.optionalNumber("dy").value_or(0.0);
        if (name == "orbit") {
            return script::Orbit{dx, dy};
        }
        if (name == "light") {
            return script::Light{dx, dy};
        }
        return script::Pan{dx, dy};
    }
    if (name == "zoom") {
        reader.allowOnly({"amount", "x", "y"});
        return script::Zoom{reader.number("amount"), reader.position()};
    }
    if (name == "pick") {
        reader.allowOnly({"x", "y"});
        return script::Pick{reader.position()};
    }
    if (name == "reset") {
        reader.allowOnly({});
        return script::Reset{};
    }
    if (name == "frame") {
        reader.allowOnly({});
        return script::FrameAll{};
    }
    if (name == "sensor") {
        reader.allowOnly({});
        return script::Sensor{};
    }
    if (name == "color") {
        reader.allowOnly({"color"});
        return script::Color{parseColoring(reader.text("color"))};
    }
    if (name == "resize") {
        reader.allowOnly({"width", "height"});
        return script::Resize{reader.integer("width", 1, kMaxWindowSide),
                              reader.integer("height", 1, kMaxWindowSide)};
    }
    if (name == "screenshot") {
        reader.allowOnly({"path"});
        return script::Screenshot{reader.text("path")};
    }
    if (name == "mode") {
        reader.allowOnly({"mode"});
        return script::SetMode{parseRenderMode(reader.text("mode"))};
    }
    if (name == "panel") {
        reader.allowOnly({"show"});
        return script::ShowPanel{reader.boolean("show")};
    }
    if (name == "settings") {
        // Whether the merged settings are possible depends on the ones in effect when the
        // action runs (a material and the coefficients it needs may come from different
        // actions), so only the form is checked here.
        reader.allowOnly({"settings"});
        return script::Settings{reader.object("settings").dump()};
    }
    if (name == "exit") {
        reader.allowOnly({});
        return script::Exit{};
    }
    throw Error(fmt::format("unknown action '{}' (expected one of {})", name, kActionNames));
}

ScriptAction parseAction(const nlohmann::json& json) {
    if (!json.is_object()) {
        throw Error("it is not an object like {\"frame\": 0, \"action\": \"orbit\", ...}");
    }
    const auto frame = json.find("frame");
    if (frame == json.end() || !frame->is_number_integer() || frame->get<long long>() < 0 ||
        frame->get<long long>() > std::numeric_limits<int>::max()) {
        throw Error("'frame' must be a whole number from 0");
    }
    const auto action = json.find("action");
    if (action == json.end() || !action->is_string()) {
        throw Error(fmt::format("'action' must be one of {}", kActionNames));
    }
    return {frame->get<int>(), parseCommand(action->get<std::string>(), ActionReader(json))};
}

}  // namespace

std::vector<ScriptAction> parseScript(const nlohmann::json& json) {
    if (!json.is_array()) {
        throw Error("a script is a list of actions: [{\"frame\": 0, \"action\": \"orbit\", ...}]");
    }
    std::vector<ScriptAction> actions;
    for (std::size_t i = 0; i < json.size(); ++i) {
        try {
            actions.push_back(parseAction(json[i]));
        } catch (const Error& error) {
            throw Error(fmt::format("action {}: {}", i + 1, error.what()));
        }
    }
    std::stable_sort(
        actions.begin(), actions.end(),
        [](const ScriptAction& a, const ScriptAction& b) { return a.frame < b.frame; });
    return actions;
}

std::vector<ScriptAction> readScriptFile(const std::filesystem::path& path) {
    std::ifstream stream(path);
    if (!stream) {
        throw Error(fmt::format("{}: cannot open the script", path.string()));
    }
    try {
        return parseScript(parseJsonText(stream));
    } catch (const Error& error) {
        throw Error(fmt::format("{}: {}", path.string(), error.what()));
    }
}

}  // namespace subscan::viewer
