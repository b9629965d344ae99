#include <string>
#include <variant>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/viewer/ViewerScript.h"
#include "core/Error.h"
#include "support/TestSupport.h"

namespace subscan::viewer {
namespace {

using ::testing::HasSubstr;

std::string scriptError(std::string_view json) {
    try {
        parseScript(nlohmann::json::parse(json));
    } catch (const Error& error) {
        return error.what();
    }
    ADD_FAILURE() << "no error for " << json;
    return {};
}

TEST(ViewerScriptTest, ReadsEveryActionInFrameOrder) {
    const auto actions = parseScript(nlohmann::json::parse(R"([
        {"frame": 5, "action": "zoom", "amount": 3},
        {"frame": 0, "action": "orbit", "dx": 100},
        {"frame": 5, "action": "zoom", "amount": -1.5, "x": 10, "y": 20},
        {"frame": 2, "action": "pan", "dx": -4, "dy": 7},
        {"frame": 6, "action": "pick"},
        {"frame": 6, "action": "pick", "x": 1, "y": 2},
        {"frame": 7, "action": "reset"},
        {"frame": 7, "action": "frame"},
        {"frame": 8, "action": "screenshot", "path": "a.png"},
        {"frame": 9, "action": "resize", "width": 320, "height": 200},
        {"frame": 9, "action": "mode", "mode": "sss"},
        {"frame": 9, "action": "panel", "show": false},
        {"frame": 10, "action": "sensor"},
        {"frame": 10, "action": "color", "color": "height"},
        {"frame": 10, "action": "exit"}
    ])"));
    ASSERT_EQ(actions.size(), 15u);
    const int frames[] = {0, 2, 5, 5, 6, 6, 7, 7, 8, 9, 9, 9, 10, 10, 10};
    for (std::size_t i = 0; i < actions.size(); ++i) {
        EXPECT_EQ(actions[i].frame, frames[i]) << "action " << i;
    }
    const auto& orbit = std::get<script::Orbit>(actions[0].command);
    EXPECT_EQ(orbit.dx, 100.0);
    EXPECT_EQ(orbit.dy, 0.0);  // absent drags are zero
    const auto& pan = std::get<script::Pan>(actions[1].command);
    EXPECT_EQ(pan.dx, -4.0);
    EXPECT_EQ(pan.dy, 7.0);
    // Same frame: the file's order.
    const auto& firstZoom = std::get<script::Zoom>(actions[2].command);
    EXPECT_EQ(firstZoom.amount, 3.0);
    EXPECT_FALSE(firstZoom.at.has_value());
    const auto& secondZoom = std::get<script::Zoom>(actions[3].command);
    EXPECT_EQ(secondZoom.amount, -1.5);
    ASSERT_TRUE(secondZoom.at.has_value());
    EXPECT_EQ(*secondZoom.at, glm::dvec2(10, 20));
    EXPECT_FALSE(std::get<script::Pick>(actions[4].command).at.has_value());
    EXPECT_EQ(*std::get<script::Pick>(actions[5].command).at, glm::dvec2(1, 2));
    EXPECT_TRUE(std::holds_alternative<script::Reset>(actions[6].command));
    EXPECT_TRUE(std::holds_alternative<script::FrameAll>(actions[7].command));
    EXPECT_EQ(std::get<script::Screenshot>(actions[8].command).path, "a.png");
    const auto& resize = std::get<script::Resize>(actions[9].command);
    EXPECT_EQ(resize.width, 320);
    EXPECT_EQ(resize.height, 200);
    EXPECT_EQ(std::get<script::SetMode>(actions[10].command).mode, RenderMode::Sss);
    EXPECT_FALSE(std::get<script::ShowPanel>(actions[11].command).show);
    EXPECT_TRUE(std::holds_alternative<script::Sensor>(actions[12].command));
    EXPECT_EQ(std::get<script::Color>(actions[13].command).coloring, Coloring::Height);
    EXPECT_TRUE(std::holds_alternative<script::Exit>(actions[14].command));
}

TEST(ViewerScriptTest, ReadsTheLightDragAndSettingsChanges) {
    const auto actions = parseScript(nlohmann::json::parse(R"([
        {"frame": 1, "action": "light", "dx": 40, "dy": -20},
        {"frame": 1, "action": "light"},
        {"frame": 2, "action": "settings",
         "settings": {"scattering": {"method": "single", "eta": null}}}
    ])"));
    ASSERT_EQ(actions.size(), 3u);
    const auto& light = std::get<script::Light>(actions[0].command);
    EXPECT_EQ(light.dx, 40.0);
    EXPECT_EQ(light.dy, -20.0);
    const auto& still = std::get<script::Light>(actions[1].command);
    EXPECT_EQ(still.dx, 0.0);  // pressing L alone: adds the light if there is none
    EXPECT_EQ(still.dy, 0.0);
    // Kept as written: a null in a merge patch removes the key (eta: back to the material's).
    EXPECT_EQ(nlohmann::json::parse(std::get<script::Settings>(actions[2].command).patch),
              nlohmann::json::parse(R"({"scattering": {"method": "single", "eta": null}})"));
}

TEST(ViewerScriptTest, RefusesWhatIsWrongNamingTheAction) {
    EXPECT_THAT(scriptError(R"({"frame": 0})"), HasSubstr("a script is a list of actions"));
    EXPECT_THAT(scriptError(R"([{"frame": 0, "action": "spin"}])"),
                HasSubstr("action 1: unknown action 'spin' (expected one of orbit, pan, zoom"));
    EXPECT_THAT(scriptError(R"([{"frame": 0, "action": "reset"}, {"action": "reset"}])"),
                HasSubstr("action 2: 'frame' must be a whole number from 0"));
    EXPECT_THAT(scriptError(R"([{"frame": -1, "action": "reset"}])"),
                HasSubstr("'frame' must be a whole number from 0"));
    EXPECT_THAT(scriptError(R"([{"frame": 1.5, "action": "reset"}])"),
                HasSubstr("'frame' must be a whole number from 0"));
    EXPECT_THAT(scriptError(R"([{"frame": 0}])"), HasSubstr("'action' must be one of"));
    EXPECT_THAT(scriptError(R"([{"frame": 0, "action": "zoom"}])"),
                HasSubstr("action 1: 'amount' is missing"));
    EXPECT_THAT(scriptError(R"([{"frame": 0, "action": "zoom", "amout": 2}])"),
                HasSubstr("unknown argument 'amout'"));
    EXPECT_THAT(scriptError(R"([{"frame": 0, "action": "orbit", "dx": "left"}])"),
                HasSubstr("'dx' must be a number"));
    EXPECT_THAT(scriptError(R"([{"frame": 0, "action": "pick", "x": 3}])"),
                HasSubstr("'x' and 'y' go together"));
    EXPECT_THAT(scriptError(R"([{"frame": 0, "action": "resize", "width": 0, "height": 10}])"),
                HasSubstr("'width' must be a whole number in 1..16384"));
    EXPECT_THAT(scriptError(R"([{"frame": 0, "action": "screenshot", "path": ""}])"),
                HasSubstr("'path' must be a non-empty string"));
    EXPECT_THAT(scriptError(R"([{"frame": 0, "action": "mode", "mode": "mesh"}])"),
                HasSubstr("render mode"));
    EXPECT_THAT(scriptError(R"([{"frame": 0, "action": "panel", "show": 1}])"),
                HasSubstr("'show' must be true or false"));
    EXPECT_THAT(scriptError(R"([{"frame": 0, "action": "light", "dz": 1}])"),
                HasSubstr("unknown argument 'dz'"));
    EXPECT_THAT(scriptError(R"([{"frame": 0, "action": "settings"}])"),
                HasSubstr("'settings' must be an object in the settings file's form"));
    EXPECT_THAT(scriptError(R"([{"frame": 0, "action": "settings", "settings": [1]}])"),
                HasSubstr("'settings' must be an object"));
    EXPECT_THAT(scriptError(R"([3])"), HasSubstr("action 1: it is not an object"));
}

TEST(ViewerScriptTest, FileErrorsNameTheFile) {
    const test::TempDir directory;
    const auto broken = directory.write("broken.json", "[{\"frame\": 0,");
    try {
        readScriptFile(broken);
        FAIL() << "no error";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), HasSubstr("broken.json: not valid JSON"));
    }
    const auto wrong = directory.write("wrong.json", R"([{"frame": 0, "action": "zoom"}])");
    try {
        readScriptFile(wrong);
        FAIL() << "no error";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), HasSubstr("wrong.json: action 1: 'amount' is missing"));
    }
    EXPECT_THROW(readScriptFile(directory / "absent.json"), Error);
    EXPECT_TRUE(readScriptFile(directory.write("empty.json", "[]")).empty());
}

}  // namespace
}  // namespace subscan::viewer
