// `subscan view` end to end: a real window on a virtual X server (Xvfb) rendered by Mesa, driven
// by --script. Each test starts its own Xvfb on a free display (Xvfb -displayfd picks it), so
// tests can run in parallel; a test is skipped with a message only when Xvfb is not installed.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "core/Camera.h"
#include "io/CameraJson.h"
#include "io/Image.h"
#include "scan/SyntheticScenes.h"
#include "scan/VirtualScanner.h"
#include "support/TestSupport.h"

extern char** environ;

namespace subscan::test {
namespace {

using ::testing::HasSubstr;

// 50,000 points load in a fraction of a second and still cover a 320x240 view.
constexpr const char* kScan = "synthetic:sculpture?points=50000";
// Every viewer run gets a frame limit, so a broken script cannot hang the test.
constexpr const char* kFrameLimit = "40";

std::optional<std::filesystem::path> findProgram(const std::string& name) {
    const char* path = std::getenv("PATH");
    std::string directories = path != nullptr ? path : "/usr/bin:/bin";
    std::size_t start = 0;
    while (start <= directories.size()) {
        const std::size_t end = std::min(directories.find(':', start), directories.size());
        const std::filesystem::path candidate =
            std::filesystem::path(directories.substr(start, end - start)) / name;
        if (access(candidate.c_str(), X_OK) == 0) {
            return candidate;
        }
        start = end + 1;
    }
    return std::nullopt;
}

/// An Xvfb server on a display it chose itself, stopped on destruction.
class VirtualDisplay {
  public:
    explicit VirtualDisplay(const std::filesystem::path& xvfb) {
        int fds[2];
        if (pipe(fds) != 0) {
            throw std::runtime_error("pipe failed");
        }
        const std::string writeFd = std::to_string(fds[1]);
        std::vector<std::string> arguments{xvfb.string(), "-displayfd",  writeFd,     "-screen",
                                           "0",           "1280x800x24", "-nolisten", "tcp"};
        std::vector<char*> argv;
        for (std::string& argument : arguments) {
            argv.push_back(argument.data());
        }
        argv.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addclose(&actions, fds[0]);
        posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
        posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
        const int spawned = posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ);
        posix_spawn_file_actions_destroy(&actions);
        close(fds[1]);
        if (spawned != 0) {
            close(fds[0]);
            throw std::runtime_error("cannot start " + xvfb.string());
        }
        // Xvfb writes the display number once it accepts connections.
        std::string number;
        pollfd ready{fds[0], POLLIN, 0};
        char byte = 0;
        while (poll(&ready, 1, 20000) > 0 && read(fds[0], &byte, 1) == 1 && byte != '\n') {
            number += byte;
        }
        close(fds[0]);
        if (number.empty()) {
            stop();
            throw std::runtime_error("Xvfb did not report a display within 20 s");
        }
        display_ = ":" + number;
    }
    ~VirtualDisplay() { stop(); }
    VirtualDisplay(const VirtualDisplay&) = delete;
    VirtualDisplay& operator=(const VirtualDisplay&) = delete;

    const std::string& display() const { return display_; }

  private:
    void stop() {
        if (pid_ > 0) {
            kill(pid_, SIGTERM);
            waitpid(pid_, nullptr, 0);
            pid_ = 0;
        }
    }

    pid_t pid_ = 0;
    std::string display_;
};

/// Share of pixels where a and b differ by more than `threshold` in some channel, within the
/// rectangle [x0, x1) x [y0, y1).
double differingFraction(const Image8& a, const Image8& b, int threshold, int x0 = 0, int y0 = 0,
                         int x1 = -1, int y1 = -1) {
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    x1 = x1 < 0 ? a.width : x1;
    y1 = y1 < 0 ? a.height : y1;
    std::size_t differing = 0;
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            const std::size_t i = 4 * (static_cast<std::size_t>(y) * a.width + x);
            for (std::size_t c = 0; c < 3; ++c) {
                if (std::abs(a.pixels[i + c] - b.pixels[i + c]) > threshold) {
                    ++differing;
                    break;
                }
            }
        }
    }
    return static_cast<double>(differing) / static_cast<double>((x1 - x0) * (y1 - y0));
}

class ViewerTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const std::optional<std::filesystem::path> xvfb = findProgram("Xvfb");
        if (!xvfb) {
            GTEST_SKIP() << "Xvfb not found: install xvfb (scripts/setup-deps.sh) to run the "
                            "viewer tests";
        }
        display_.emplace(*xvfb);
    }

    /// `subscan view` on this test's display.
    CommandResult view(std::vector<std::string> arguments) const {
        arguments.insert(arguments.begin(), "view");
        return runSubscan(arguments, {"DISPLAY=" + display_->display()});
    }

    std::filesystem::path writeScript(const nlohmann::json& script) const {
        return directory_.write("script.json", script.dump(2));
    }

    std::string path(std::string_view name) const { return (directory_ / name).string(); }

    /// The viewer's screenshot `shot`.png is what `subscan render` draws of `scan` with the
    /// camera and settings files written beside it.
    void expectRendersPicture(const std::string& scan, const std::string& shot) const {
        SCOPED_TRACE(shot);
        const CommandResult render =
            runSubscan({"render", scan, "-o", path(shot + "-rendered.png"), "--camera",
                        path(shot + ".camera.json"), "--settings", path(shot + ".settings.json")});
        ASSERT_EQ(render.exitCode, 0) << render.err;
        // Only where atomics resolve a tie between points differently.
        EXPECT_LT(differingFraction(readPng(path(shot + ".png")),
                                    readPng(path(shot + "-rendered.png")), 8),
                  0.005);
    }
    std::string writeSettings(const std::string& name, const std::string& json) const {
        return directory_.write(name, json).string();
    }
    /// Settings that turn the viewer's temporal filter off: one frame per change.
    std::string withoutTemporalFilter() const {
        return directory_.write("no-temporal.json", R"({"temporal": {"enabled": false}})").string();
    }

    TempDir directory_;
    std::optional<VirtualDisplay> display_;
};

/// The viewer's default background, sRGB 0.19 as 8 bits.
constexpr int kBackground = 48;

/// Share of pixels that are not the background (more than a small step away in any channel).
double foregroundFraction(const Image8& image) {
    std::size_t foreground = 0;
    const std::size_t pixels = image.pixels.size() / 4;
    for (std::size_t i = 0; i < pixels; ++i) {
        for (std::size_t c = 0; c < 3; ++c) {
            if (std::abs(image.pixels[4 * i + c] - kBackground) > 6) {
                ++foreground;
                break;
            }
        }
    }
    return static_cast<double>(foreground) / static_cast<double>(pixels);
}

TEST_F(ViewerTest, ScriptedOrbitAndZoomMoveTheCameraAndScreenshotsShowIt) {
    const auto script = writeScript(nlohmann::json::array({
        {{"frame", 0}, {"action", "screenshot"}, {"path", path("start.png")}},
        {{"frame", 1}, {"action", "orbit"}, {"dx", 150}, {"dy", 0}},
        {{"frame", 1}, {"action", "screenshot"}, {"path", path("orbited.png")}},
        {{"frame", 2}, {"action", "pick"}},
        {{"frame", 2}, {"action", "zoom"}, {"amount", 3}},
        {{"frame", 2}, {"action", "screenshot"}, {"path", path("zoomed.png")}},
        {{"frame", 3}, {"action", "panel"}, {"show", true}},
        {{"frame", 3}, {"action", "screenshot"}, {"path", path("panel.png")}},
        {{"frame", 3}, {"action", "exit"}},
    }));
    // One frame per change, so that each screenshot is the frame its action caused.
    const CommandResult result =
        view({kScan, "--mode", "surface", "--width", "320", "--height", "240", "--hide-panel",
              "--script", script.string(), "--exit-after-frames", kFrameLimit, "--settings",
              withoutTemporalFilter()});
    ASSERT_EQ(result.exitCode, 0) << result.err;

    const Image8 start = readPng(path("start.png"));
    const Image8 orbited = readPng(path("orbited.png"));
    const Image8 zoomed = readPng(path("zoomed.png"));
    const Image8 panel = readPng(path("panel.png"));
    for (const Image8* image : {&start, &orbited, &zoomed, &panel}) {
        EXPECT_EQ(image->width, 320);
        EXPECT_EQ(image->height, 240);
    }
    // The framed sculpture covers about a sixth of the view; a blank or black window would not.
    EXPECT_GT(foregroundFraction(start), 0.08);
    EXPECT_GT(foregroundFraction(orbited), 0.08);
    // Half a turn around the sculpture changes much of what is on screen.
    EXPECT_GT(differingFraction(start, orbited, 24), 0.03);
    // Three wheel steps at the middle of the window bring the surface there closer: it grows.
    EXPECT_GT(foregroundFraction(zoomed), 1.5 * foregroundFraction(orbited));
    // The panel covers the top left corner, and only the panel changed.
    EXPECT_GT(differingFraction(zoomed, panel, 24, 8, 8, 120, 40), 0.3);
    EXPECT_LT(differingFraction(zoomed, panel, 0, 240, 0, 320, 240), 0.001);

    // Each screenshot has its camera and settings beside it: `subscan render` makes the same
    // picture headless (EGL) with the same pipeline.
    ASSERT_TRUE(std::filesystem::exists(path("orbited.camera.json")));
    ASSERT_TRUE(std::filesystem::exists(path("orbited.settings.json")));
    const CommandResult render =
        runSubscan({"render", kScan, "-o", path("rendered.png"), "--camera",
                    path("orbited.camera.json"), "--settings", path("orbited.settings.json")});
    ASSERT_EQ(render.exitCode, 0) << render.err;
    // Both run on llvmpipe; a pixel may only differ where atomics resolve a tie differently.
    EXPECT_LT(differingFraction(orbited, readPng(path("rendered.png")), 8), 0.005);
}

TEST_F(ViewerTest, TheColouringChoiceRecoloursThePointsAsRenderDoes) {
    const auto script = writeScript(nlohmann::json::array({
        {{"frame", 0}, {"action", "screenshot"}, {"path", path("own.png")}},
        {{"frame", 1}, {"action", "color"}, {"color", "height"}},
        {{"frame", 1}, {"action", "screenshot"}, {"path", path("height.png")}},
        {{"frame", 1}, {"action", "exit"}},
    }));
    const CommandResult result =
        view({kScan, "--mode", "surface", "--width", "320", "--height", "240", "--hide-panel",
              "--script", script.string(), "--exit-after-frames", kFrameLimit, "--settings",
              withoutTemporalFilter()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const Image8 own = readPng(path("own.png"));
    const Image8 height = readPng(path("height.png"));
    // The sculpture's own marble against the height ramp: most of its pixels change.
    EXPECT_GT(differingFraction(own, height, 24), 0.5 * foregroundFraction(own));
    // `subscan render --color height` from the screenshot's camera makes the same picture.
    const CommandResult render =
        runSubscan({"render", kScan, "-o", path("rendered.png"), "--color", "height", "--camera",
                    path("height.camera.json"), "--settings", path("height.settings.json")});
    ASSERT_EQ(render.exitCode, 0) << render.err;
    // Both run on llvmpipe; a pixel may only differ where atomics resolve a tie differently.
    EXPECT_LT(differingFraction(height, readPng(path("rendered.png")), 8), 0.005);
}

TEST_F(ViewerTest, TheSensorActionLooksFromTheVirtualStation) {
    const std::string station = "synthetic:outdoor-station?points=20000";
    const auto script = writeScript(nlohmann::json::array({
        {{"frame", 0}, {"action", "sensor"}},
        {{"frame", 0}, {"action", "screenshot"}, {"path", path("sensor.png")}},
        {{"frame", 0}, {"action", "exit"}},
    }));
    const CommandResult result =
        view({station, "--mode", "surface", "--width", "160", "--height", "120", "--hide-panel",
              "--script", script.string(), "--exit-after-frames", kFrameLimit});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const Camera camera = readCameraFile(path("sensor.camera.json"));
    const SyntheticSource source = makeSyntheticSource("outdoor-station?points=20000");
    // camera.json keeps the view matrix in double: the eye is the station to rounding.
    EXPECT_LT(glm::length(camera.eye() - stationPosition(*source.scene, source.scanner.station)),
              1e-6);
    EXPECT_GT(foregroundFraction(readPng(path("sensor.png"))), 0.3);  // it sees the scene
    // Looking where `render --view sensor` looks (the field of view is the viewer's own).
    const CommandResult render =
        runSubscan({"render", station, "--view", "sensor", "--mode", "points", "-o",
                    path("render.png"), "--export-buffers", path("render")});
    ASSERT_EQ(render.exitCode, 0) << render.err;
    const Camera rendered = readCameraFile(path("render/camera.json"));
    const auto forward = [](const Camera& c) { return glm::dvec3(glm::inverse(c.view)[2]); };
    EXPECT_NEAR(glm::dot(forward(camera), forward(rendered)), 1.0, 1e-9);
}

TEST_F(ViewerTest, ResizingTheWindowReallocatesThePipeline) {
    const auto script = writeScript(nlohmann::json::array({
        {{"frame", 0}, {"action", "screenshot"}, {"path", path("small.png")}},
        {{"frame", 1}, {"action", "resize"}, {"width", 400}, {"height", 300}},
        {{"frame", 1}, {"action", "screenshot"}, {"path", path("larger.png")}},
        {{"frame", 2}, {"action", "resize"}, {"width", 200}, {"height", 260}},
        {{"frame", 2}, {"action", "frame"}},
        {{"frame", 2}, {"action", "screenshot"}, {"path", path("narrow.png")}},
    }));
    const CommandResult result =
        view({kScan, "--mode", "surface", "--width", "320", "--height", "240", "--hide-panel",
              "--script", script.string(), "--exit-after-frames", "4", "--screenshot",
              path("exit.png")});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_THAT(result.err, ::testing::Not(HasSubstr("error")));

    const Image8 small = readPng(path("small.png"));
    const Image8 larger = readPng(path("larger.png"));
    const Image8 narrow = readPng(path("narrow.png"));
    const Image8 exit = readPng(path("exit.png"));
    EXPECT_EQ(small.width, 320);
    EXPECT_EQ(small.height, 240);
    EXPECT_EQ(larger.width, 400);
    EXPECT_EQ(larger.height, 300);
    EXPECT_EQ(narrow.width, 200);
    EXPECT_EQ(narrow.height, 260);
    EXPECT_EQ(exit.width, 200);
    EXPECT_EQ(exit.height, 260);
    for (const Image8* image : {&small, &larger, &narrow}) {
        EXPECT_GT(foregroundFraction(*image), 0.08);
    }
}

nlohmann::json readJsonFile(const std::filesystem::path& file) {
    std::ifstream stream(file);
    EXPECT_TRUE(stream) << file;
    return nlohmann::json::parse(stream, nullptr, false);
}

/// The direction of the first directional light in a screenshot's settings file.
glm::dvec3 firstLightDirection(const std::filesystem::path& settings) {
    const nlohmann::json json = readJsonFile(settings);
    const nlohmann::json& direction = json.at("shading").at("lights").at(0).at("direction");
    return {direction.at(0).get<double>(), direction.at(1).get<double>(),
            direction.at(2).get<double>()};
}

TEST_F(ViewerTest, ACameraAtRestRefinesToTheAntiAliasedStill) {
    // The viewer's default: the temporal filter on. Untouched, it renders 32 frames through
    // sub-pixel offsets and then idles; its picture is then `render`'s with the same files.
    const auto script = writeScript(nlohmann::json::array({
        {{"frame", 0}, {"action", "screenshot"}, {"path", path("first.png")}},
        {{"frame", 36}, {"action", "screenshot"}, {"path", path("rest.png")}},
        {{"frame", 36}, {"action", "exit"}},
    }));
    const CommandResult result =
        view({kScan, "--mode", "surface", "--width", "320", "--height", "240", "--hide-panel",
              "--script", script.string(), "--exit-after-frames", kFrameLimit});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const Image8 first = readPng(path("first.png"));
    const Image8 rest = readPng(path("rest.png"));
    // The silhouettes soften: a few percent of the pixels change by more than a level.
    EXPECT_GT(differingFraction(first, rest, 1), 0.005);
    EXPECT_EQ(readJsonFile(path("rest.settings.json"))["temporal"]["enabled"], true);
    const CommandResult render =
        runSubscan({"render", kScan, "-o", path("rendered.png"), "--camera",
                    path("rest.camera.json"), "--settings", path("rest.settings.json")});
    ASSERT_EQ(render.exitCode, 0) << render.err;
    // As above: only where atomics resolve a tie differently.
    EXPECT_LT(differingFraction(rest, readPng(path("rendered.png")), 8), 0.005);
}

TEST_F(ViewerTest, AStreamedSurveyShowsTheNodesItsViewSelects) {
    // A COPC file opens as its overview (the top levels) and then loads the nodes the view
    // selects within the budget; unattended runs wait for them, so every frame is `render`'s.
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const std::string scan = (data / "lone_star.copc.laz").string();
    const auto script = writeScript(nlohmann::json::array({
        {{"frame", 0}, {"action", "screenshot"}, {"path", path("framed.png")}},
        {{"frame", 1}, {"action", "zoom"}, {"amount", 4}},
        {{"frame", 1}, {"action", "screenshot"}, {"path", path("near.png")}},
        {{"frame", 2}, {"action", "exit"}},
    }));
    // A MiB a frame: the view's local spacing (8 bytes a point, some 4 MB) goes to the GPU
    // over several frames, which show the overview and do not count.
    const std::string settings = writeSettings("upload.json", R"({"temporal": {"enabled": false},
                                         "streaming": {"upload_megabytes_per_frame": 1}})");
    const CommandResult result = view({scan, "--mode", "surface", "--width", "320", "--height",
                                       "240", "--hide-panel", "--script", script.string(),
                                       "--exit-after-frames", kFrameLimit, "--settings", settings});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    // The view's 4 MB at 1 MiB a frame: at least 4 frames uploaded (1 at the default 32 MiB).
    std::smatch uploads;
    ASSERT_TRUE(std::regex_search(result.err, uploads, std::regex("(\\d+) frames uploaded")))
        << result.err;
    EXPECT_GE(std::stoi(uploads[1]), 4) << result.err;
    // The overview alone (164,000 of the 518,862 points) differs in 5 to 6 % of the pixels
    // (measured).
    for (const std::string shot : {"framed", "near"}) {
        expectRendersPicture(scan, shot);
    }
}

TEST_F(ViewerTest, ChangingTheLevelsOfDetailOpensTheScanAgain) {
    // streaming.lod decides when a scan opens; a script's change (as the panel's combo, or a
    // loaded settings file) opens it again, and an unattended run counts no frame until then.
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const std::string scan = (data / "lone_star.copc.laz").string();
    // A budget of a fifth of the points: the streamed view differs from the whole file.
    const std::string settings = writeSettings("budget.json", R"({"temporal": {"enabled": false},
                                         "streaming": {"point_budget": 100000}})");
    const auto script = writeScript(nlohmann::json::array({
        {{"frame", 0}, {"action", "screenshot"}, {"path", path("streamed.png")}},
        {{"frame", 1}, {"action", "settings"}, {"settings", {{"streaming", {{"lod", "off"}}}}}},
        {{"frame", 2}, {"action", "screenshot"}, {"path", path("whole.png")}},
        {{"frame", 3}, {"action", "exit"}},
    }));
    const CommandResult result = view({scan, "--mode", "surface", "--width", "320", "--height",
                                       "240", "--hide-panel", "--script", script.string(),
                                       "--exit-after-frames", kFrameLimit, "--settings", settings});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_EQ(readJsonFile(path("whole.settings.json"))["streaming"]["lod"], "off");
    for (const std::string shot : {"streamed", "whole"}) {
        expectRendersPicture(scan, shot);
    }
    // The whole file is not the streamed view: a fifth of the points fill coarser (measured:
    // 17 % of the pixels differ).
    EXPECT_GT(differingFraction(readPng(path("streamed.png")), readPng(path("whole.png")), 8),
              0.05);
}

TEST_F(ViewerTest, SingleScatteringRendersAndLDragsTurnTheLightNotTheView) {
    // The sculpture is 29 cm tall in metres (the default unit): marble's mean free paths of
    // 4-9 mm show.
    const auto script = writeScript(nlohmann::json::array({
        {{"frame", 0}, {"action", "screenshot"}, {"path", path("single.png")}},
        // Pressing L adds a light from the upper left of the view.
        {{"frame", 1}, {"action", "light"}},
        {{"frame", 1}, {"action", "screenshot"}, {"path", path("lit.png")}},
        // An L drag of a quarter turn to the right.
        {{"frame", 2}, {"action", "light"}, {"dx", 300}, {"dy", 0}},
        {{"frame", 2}, {"action", "screenshot"}, {"path", path("turned.png")}},
        {{"frame", 3},
         {"action", "settings"},
         {"settings", {{"scattering", {{"coefficients", "material"}, {"material", "skin1"}}}}}},
        {{"frame", 3}, {"action", "screenshot"}, {"path", path("skin1.png")}},
        {{"frame", 4}, {"action", "exit"}},
    }));
    const CommandResult result =
        view({kScan, "--mode", "sss", "--scattering", "single", "--width", "320", "--height", "240",
              "--hide-panel", "--script", script.string(), "--exit-after-frames", kFrameLimit,
              "--settings", withoutTemporalFilter()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_THAT(result.err, HasSubstr("added light 1"));

    const Image8 single = readPng(path("single.png"));
    const Image8 lit = readPng(path("lit.png"));
    const Image8 turned = readPng(path("turned.png"));
    const Image8 skin1 = readPng(path("skin1.png"));
    for (const Image8* image : {&single, &lit, &turned, &skin1}) {
        EXPECT_GT(foregroundFraction(*image), 0.08);
    }
    // The added light and its turn change the lit surface; so do other coefficients.
    EXPECT_GT(differingFraction(single, lit, 8), 0.02);
    EXPECT_GT(differingFraction(lit, turned, 8), 0.02);
    EXPECT_GT(differingFraction(turned, skin1, 8), 0.01);

    // The view stayed where it was; the light turned by a quarter.
    EXPECT_EQ(readJsonFile(path("lit.camera.json")), readJsonFile(path("turned.camera.json")));
    EXPECT_EQ(readJsonFile(path("single.camera.json")), readJsonFile(path("turned.camera.json")));
    const glm::dvec3 added = firstLightDirection(path("lit.settings.json"));
    const glm::dvec3 moved = firstLightDirection(path("turned.settings.json"));
    EXPECT_NEAR(glm::length(added), 1.0, 1e-6);
    EXPECT_NEAR(glm::length(moved), 1.0, 1e-6);
    // From the upper left (-1, 1, 1 in the view's right, up, towards-the-eye) a quarter turn
    // around the view's up axis goes to the upper right (1, 1, 1): the move is along the view's
    // right, which is level for this orbit around the y axis.
    EXPECT_NEAR(glm::dot(added, moved), 1.0 / 3.0, 1e-4);
    EXPECT_NEAR(moved.y - added.y, 0.0, 1e-4);

    // The screenshot's files give `subscan render` the same picture.
    const CommandResult render =
        runSubscan({"render", kScan, "-o", path("rendered.png"), "--camera",
                    path("turned.camera.json"), "--settings", path("turned.settings.json")});
    ASSERT_EQ(render.exitCode, 0) << render.err;
    EXPECT_LT(differingFraction(turned, readPng(path("rendered.png")), 8), 0.005);
}

TEST_F(ViewerTest, SingleScatteringFromAGaussianOnlyMaterialEndsARunWithTheSentence) {
    // Interactively the panel shows the sentence and keeps the last good scattering settings
    // (ViewerPanelTest); a scripted run ends with it, as every error the panel shows.
    const auto script = writeScript(nlohmann::json::array({
        {{"frame", 0}, {"action", "screenshot"}, {"path", path("before.png")}},
        {{"frame", 1},
         {"action", "settings"},
         {"settings", {{"scattering", {{"coefficients", "material"}, {"material", "skin-deon"}}}}}},
        {{"frame", 1}, {"action", "screenshot"}, {"path", path("after.png")}},
    }));
    const CommandResult result =
        view({kScan, "--mode", "sss", "--scattering", "single", "--width", "320", "--height", "240",
              "--hide-panel", "--script", script.string(), "--exit-after-frames", kFrameLimit});
    EXPECT_EQ(result.exitCode, 1);
    // One sentence, once, and last (after the screenshot's notice); no crash, no repetition.
    const std::string sentence =
        "subscan: the material 'skin-deon' is a Gaussian set without measured";
    EXPECT_THAT(result.err, HasSubstr(sentence));
    EXPECT_EQ(result.err.find(sentence), result.err.rfind(sentence)) << result.err;
    EXPECT_EQ(result.err.find('\n', result.err.find(sentence)), result.err.size() - 1)
        << result.err;
    EXPECT_GT(foregroundFraction(readPng(path("before.png"))), 0.08);
    EXPECT_FALSE(std::filesystem::exists(path("after.png")));
}

TEST_F(ViewerTest, MissingScanFailsWithOneSentence) {
    const CommandResult result = view({path("absent.ply")});
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_THAT(result.err, HasSubstr("absent.ply: cannot open the file"));
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
}

TEST_F(ViewerTest, SceneThatCannotBeMadeFailsOnceTheWindowIsOpen) {
    // Synthetic scenes are made by the loading thread, after the window opened.
    const CommandResult result = view({"synthetic:teapot", "--exit-after-frames", kFrameLimit});
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_THAT(result.err, HasSubstr("synthetic:teapot"));
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
}

TEST(ViewerWithoutDisplayTest, NoDisplayFailsWithTheClearSentence) {
    // An empty DISPLAY is how runSubscan unsets it: X11 treats both alike.
    const CommandResult unset = runSubscan({"view", kScan}, {"DISPLAY="});
    EXPECT_EQ(unset.exitCode, 1);
    EXPECT_EQ(unset.err,
              "subscan: cannot open a window: no display (set DISPLAY, or use `subscan render` "
              "headless)\n");

    const CommandResult unreachable = runSubscan({"view", kScan}, {"DISPLAY=:64999"});
    EXPECT_EQ(unreachable.exitCode, 1);
    EXPECT_THAT(unreachable.err,
                HasSubstr("subscan: cannot open a window: cannot connect to the display ':64999'"));
    EXPECT_EQ(std::count(unreachable.err.begin(), unreachable.err.end(), '\n'), 1)
        << unreachable.err;
}

TEST(ViewerWithoutDisplayTest, BadScriptOrOptionsFailBeforeAnyWindow) {
    const TempDir directory;
    const auto script =
        directory.write("script.json", R"([{"frame": 0, "action": "zoom", "amout": 2}])");
    const CommandResult badScript =
        runSubscan({"view", kScan, "--script", script.string()}, {"DISPLAY="});
    EXPECT_EQ(badScript.exitCode, 1);
    EXPECT_THAT(badScript.err, HasSubstr("script.json: action 1: unknown argument 'amout'"));

    const CommandResult badMaterial =
        runSubscan({"view", kScan, "--material", "cheese"}, {"DISPLAY="});
    EXPECT_EQ(badMaterial.exitCode, 2);  // a bad option value: a usage error
    EXPECT_THAT(badMaterial.err, HasSubstr("--material: there is no material 'cheese'"));

    const CommandResult badUsage = runSubscan({"view", kScan, "--mode", "mesh"});
    EXPECT_EQ(badUsage.exitCode, 2);
}

}  // namespace
}  // namespace subscan::test
