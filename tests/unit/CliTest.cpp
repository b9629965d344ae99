#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/Spacing.h"
#include "io/ScanLoader.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::runSubscan;
using ::testing::HasSubstr;

TEST(CliTest, UsageErrorsExitWithTwo) {
    EXPECT_EQ(runSubscan({}).exitCode, 2);
    EXPECT_EQ(runSubscan({"info"}).exitCode, 2);
    EXPECT_EQ(runSubscan({"frobnicate"}).exitCode, 2);
    EXPECT_EQ(runSubscan({"info", "synthetic:sphere", "--no-such-option"}).exitCode, 2);
    EXPECT_EQ(runSubscan({"--help"}).exitCode, 0);
}

TEST(CliTest, NumbersThatAreNotFiniteAreRefused) {
    // CLI11 reads them as numbers and its range checks let NaN through: the picture was empty,
    // eval's PSNR 100 dB, and the exit 0.
    const std::vector<std::vector<std::string>> cases{
        {"render", "synthetic:sphere", "-o", "x.png", "--yaw", "nan"},
        {"render", "synthetic:sphere", "-o", "x.png", "--pitch", "nan"},
        {"render", "synthetic:sphere", "-o", "x.png", "--fovy", "inf"},
        {"render", "synthetic:sphere", "-o", "x.png", "--distance", "1e999"},
        {"render", "synthetic:sphere", "-o", "x.png", "--eta", "nan"},
        {"eval", "synthetic:sphere", "--distance", "nan"},
        {"eval", "synthetic:sphere", "--temporal", "--step", "nan"},
        {"turntable", "synthetic:sphere", "-o", "frames", "--degrees", "-inf"},
    };
    for (const auto& arguments : cases) {
        const test::CommandResult result = runSubscan(arguments);
        EXPECT_EQ(result.exitCode, 2) << arguments.back();
        EXPECT_THAT(result.err, HasSubstr("is not a finite number")) << arguments.back();
    }
}

TEST(CliTest, BadScatteringValuesNameTheirOptionAsUsageErrors) {
    // They were refused after the parse, with exit 1, naming the settings' key ('eta') for an
    // option the user had typed as --eta. Refused while parsing, nothing renders.
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
        {{"--sss-scale", "0"}, "--sss-scale: 0 is outside 0..1000 (exclusive of 0)"},
        {{"--sss-scale", "-1"}, "--sss-scale: -1 is outside 0..1000 (exclusive of 0)"},
        {{"--mean-free-path", "1,-2,3"},
         "--mean-free-path: 1,-2,3 must be positive millimetres in every channel, not -2"},
        {{"--eta", "0.5"}, "--eta: 0.5 is outside 1..3"},
        {{"--phase-g", "1"}, "--phase-g: 1 must lie strictly between -1 and 1"},
        {{"--single-samples", "0"}, "--single-samples: 0 is outside 1..64"},
        {{"--material", "jade"}, "--material: there is no material 'jade'"},
    };
    for (const std::string command : {"render", "turntable", "bench", "view"}) {
        for (const auto& [option, message] : cases) {
            std::vector<std::string> arguments{command, "synthetic:sphere", "--mode", "sss"};
            if (command == "render" || command == "turntable") {
                arguments.insert(arguments.end(), {"-o", "never-written"});
            }
            arguments.insert(arguments.end(), option.begin(), option.end());
            const test::CommandResult result = runSubscan(arguments);
            EXPECT_EQ(result.exitCode, 2) << command << " " << option.front();
            EXPECT_THAT(result.err, ::testing::StartsWith(message)) << command;
        }
    }
    EXPECT_FALSE(std::filesystem::exists("never-written"));

    // From a settings file the value is named by its key in the file.
    const test::TempDir dir;
    const auto settings = dir.write("settings.json", R"({"scattering": {"eta": 0.5}})");
    const test::CommandResult fromFile =
        runSubscan({"render", "synthetic:sphere", "-o", (dir / "x.png").string(), "--settings",
                    settings.string()});
    EXPECT_EQ(fromFile.exitCode, 1);
    EXPECT_EQ(fromFile.err, "subscan: " + settings.string() +
                                ": the setting 'eta' = 0.5 is outside 1..3 (the relative index of "
                                "refraction of a medium denser than air)\n");
}

TEST(CliTest, ABadBackgroundIsAUsageErrorNamingTheOption) {
    // It exited 1 after the parse; refused while parsing, nothing renders.
    for (const std::string command : {"render", "turntable"}) {
        for (const std::string colour : {"2,2,2", "0.5,0.5", "#12345g", "red"}) {
            const test::CommandResult result = runSubscan(
                {command, "synthetic:sphere", "-o", "never-written", "--background", colour});
            EXPECT_EQ(result.exitCode, 2) << command << " " << colour;
            EXPECT_THAT(result.err, ::testing::StartsWith("--background: '" + colour +
                                                          "' is not R,G,B with values in 0..1 "
                                                          "or #rrggbb"))
                << command;
        }
    }
    EXPECT_FALSE(std::filesystem::exists("never-written"));
}

TEST(CliTest, ABadModesListIsAUsageErrorNamingTheOption) {
    // bench refused it with exit 1 once the command had started; refused while parsing, nothing
    // renders.
    const std::vector<std::pair<std::string, std::string>> cases{
        {"surface,sss:fast",
         "--modes: 'fast' in 'sss:fast' is neither a scattering method of the sss mode "
         "(sss:gaussian, sss:single or sss:both) nor no-shadows (surface and sss)"},
        {"surface:single", "--modes: 'single' in 'surface:single' is neither"},
        {"points:no-shadows", "--modes: 'no-shadows' in 'points:no-shadows' is neither"},
        {"sss:single:both", "--modes: 'both' in 'sss:single:both' is neither"},
        {"surface,voxels", "--modes: 'voxels' is not a render mode"},
        {"sss:single,sss:single", "--modes: 'sss:single' is named twice"},
    };
    for (const auto& [modes, message] : cases) {
        const test::CommandResult result =
            runSubscan({"bench", "synthetic:sphere", "--frames", "2", "--modes", modes});
        EXPECT_EQ(result.exitCode, 2) << modes;
        EXPECT_THAT(result.err, ::testing::StartsWith(message)) << modes;
    }
}

TEST(CliTest, ACameraFileExcludesTheOptionsItFixes) {
    // The file's size and view won without a word: --width 640 rendered at the file's width.
    const test::TempDir dir;
    const std::string camera = dir.write("camera.json", "{}").string();
    for (const std::string option :
         {"--width", "--height", "--yaw", "--pitch", "--distance", "--fovy"}) {
        const test::CommandResult result = runSubscan(
            {"render", "synthetic:sphere", "-o", "x.png", "--camera", camera, option, "40"});
        EXPECT_EQ(result.exitCode, 2) << option;
        EXPECT_THAT(result.err, HasSubstr("excludes --camera")) << option;
    }
}

TEST(CliTest, OptionsTheViewWouldIgnoreAreRefused) {
    // Accepted and ignored without a word (found by an outside test). Those the mode ignores
    // are named in a warning: RenderCommandGLTest, since those pictures are drawn.
    const test::TempDir dir;
    const std::string out = (dir / "x.png").string();
    auto render = [&](const std::vector<std::string>& options) {
        return test::renderSmallSphere(out, options);
    };
    // The sensor's view has no orbit.
    for (const std::string option : {"--yaw", "--pitch", "--distance"}) {
        const test::CommandResult result =
            render({"--view", "sensor", "--sensor", "0,0,5", option, "10"});
        EXPECT_EQ(result.exitCode, 1) << option;
        EXPECT_THAT(result.err, HasSubstr(option + " has no effect with --view sensor")) << option;
    }
    const test::CommandResult sensorAlone = render({"--sensor", "0,0,5"});
    EXPECT_EQ(sensorAlone.exitCode, 1);
    EXPECT_THAT(sensorAlone.err, HasSubstr("add --view sensor"));
    EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliTest, InfoJsonHasExactlyTheDocumentedKeys) {
    const test::CommandResult result = runSubscan({"info", "synthetic:sphere", "--json"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const nlohmann::json info = nlohmann::json::parse(result.out);
    std::vector<std::string> keys;
    for (const auto& [key, value] : info.items()) {
        keys.push_back(key);
    }
    EXPECT_THAT(keys, ::testing::UnorderedElementsAre("format", "format_detail", "points",
                                                      "bounds_min", "bounds_max", "attributes",
                                                      "faces", "spacing", "load_ms"));
    EXPECT_EQ(info["format"], "synthetic");
    EXPECT_THAT(info["format_detail"].get<std::string>(), HasSubstr("sphere"));
    EXPECT_EQ(info["points"], 4000);
    // A virtual scan: the scene's colour and the true normals.
    EXPECT_EQ(info["attributes"], nlohmann::json({"position", "color", "normal"}));
    EXPECT_EQ(info["faces"], 0);
    // The command reports the library's estimate (JSON keeps every digit)...
    EXPECT_DOUBLE_EQ(info["spacing"].get<double>(),
                     estimateSpacing(loadScan("synthetic:sphere").cloud));
    // ...which for 4000 points on the unit sphere is below the spacing of an ideal hexagonal
    // packing, sqrt(8 pi / (sqrt(3) 4000)) = 0.060: overlapping views interleave their grids,
    // bringing neighbours closer, but not by an order of magnitude.
    EXPECT_LT(info["spacing"].get<double>(), 0.060);
    EXPECT_GT(info["spacing"].get<double>(), 0.006);
    EXPECT_GE(info["load_ms"].get<double>(), 0.0);
}

TEST(CliTest, ErrorsAreOneLineNamingTheFile) {
    const test::TempDir dir;
    const auto truncated = dir.write("cut.ply",
                                     "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                     "property float y\nproperty float z\nend_header\n1 2 3\n");
    const test::CommandResult result = runSubscan({"info", truncated.string()});
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_TRUE(result.out.empty());
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_THAT(result.err, HasSubstr("cut.ply: the PLY body ends inside vertex 2 of 2"));
}

TEST(CliTest, WarningsGoToStderrAndTheCommandSucceeds) {
    const test::TempDir dir;
    const auto withNan =
        dir.write("nan.ply",
                  "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                  "property float y\nproperty float z\nend_header\n1 2 3\nnan 0 0\n");
    const test::CommandResult result = runSubscan({"info", withNan.string(), "--json"});
    EXPECT_EQ(result.exitCode, 0);
    EXPECT_THAT(result.err, HasSubstr("warning: " + withNan.string() + ": dropped 1 of 2"));
    EXPECT_EQ(nlohmann::json::parse(result.out)["points"], 1);
}

}  // namespace
}  // namespace subscan
