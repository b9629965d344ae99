// `subscan turntable`: numbered PNGs or an MP4 through the temporal filter, the first frame
// already converged, the yaw growing by degrees / frames, per-frame buffers, and refusals.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/Image.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::runSubscan;
using ::testing::HasSubstr;

const std::vector<std::string> kScene = {
    "synthetic:sphere?points=4000", "--mode", "surface", "--width", "40", "--height", "32"};

std::vector<std::string> with(std::vector<std::string> arguments,
                              const std::vector<std::string>& more) {
    arguments.insert(arguments.end(), more.begin(), more.end());
    return arguments;
}

TEST(TurntableCommandGLTest, FramesStartConvergedAndTurnByDegreesOverFrames) {
    const test::TempDir dir;
    const auto turntable = runSubscan(
        with(with({"turntable"}, kScene),
             {"-o", (dir / "frames").string(), "--frames", "3", "--degrees", "90", "--yaw", "10",
              "--distance", "3", "--export-buffers", (dir / "buffers").string()}));
    ASSERT_EQ(turntable.exitCode, 0) << turntable.err;
    for (const char* name : {"0000.png", "0001.png", "0002.png"}) {
        EXPECT_TRUE(std::filesystem::is_regular_file(dir / "frames" / name)) << name;
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "frames" / "0003.png"));

    // (The same --distance for both: render frames the box from its one view, a turntable the
    // bounding sphere, which holds for every yaw.)
    // Frame 0 is the still the filter converges to over its 16 warm-up frames: the same
    // picture, bit for bit, as `render --samples 16` from that camera (exporting too, so that
    // both run the pass-by-pass chain, whose half floats round unlike FinishSurface).
    const auto still =
        runSubscan(with(with({"render"}, kScene), {"--yaw", "10", "--distance", "3", "--samples",
                                                   "16", "-o", (dir / "still.png").string(),
                                                   "--export-buffers", (dir / "still").string()}));
    ASSERT_EQ(still.exitCode, 0) << still.err;
    EXPECT_EQ(test::fileBytes(dir / "frames" / "0000.png"), test::fileBytes(dir / "still.png"));

    // Frame 2's camera is render's at yaw 10 + 2 x 90 / 3, without jitter.
    const auto render =
        runSubscan(with(with({"render"}, kScene),
                        {"--yaw", "70", "--distance", "3", "-o", (dir / "yaw70.png").string(),
                         "--export-buffers", (dir / "yaw70").string()}));
    ASSERT_EQ(render.exitCode, 0) << render.err;
    const nlohmann::json expected =
        nlohmann::json::parse(test::fileBytes(dir / "yaw70" / "camera.json"));
    const nlohmann::json actual =
        nlohmann::json::parse(test::fileBytes(dir / "buffers" / "0002" / "camera.json"));
    for (const char* matrix : {"view", "projection"}) {
        for (int r = 0; r < 4; ++r) {
            for (int c = 0; c < 4; ++c) {
                // Turning the scene about the centre instead of orbiting the eye: the same
                // matrix up to double rounding.
                EXPECT_NEAR(actual[matrix][r][c].get<double>(),
                            expected[matrix][r][c].get<double>(), 1e-9)
                    << matrix << "[" << r << "][" << c << "]";
            }
        }
    }
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / "buffers" / "0002" / "depth.pfm"));
}

// A settings file names what it changes: one without a mode still turns the surface, one that
// names the points mode turns points (the surface modes alone export normals).
TEST(TurntableCommandGLTest, TurnsTheSurfaceUnlessAModeIsNamed) {
    const test::TempDir dir;
    const std::pair<const char*, const char*> cases[] = {
        {"weight.json", R"({"temporal": {"new_frame_weight": 0.3}})"},
        {"points.json", R"({"raster": {"mode": "points"}})"}};
    for (const auto& [name, text] : cases) {
        std::ofstream(dir / name) << text;
        const auto turntable =
            runSubscan({"turntable", "synthetic:sphere?points=4000", "--width", "40", "--height",
                        "32", "--frames", "1", "--settings", (dir / name).string(), "-o",
                        (dir / name).string() + ".frames", "--export-buffers",
                        (dir / name).string() + ".buffers"});
        ASSERT_EQ(turntable.exitCode, 0) << turntable.err;
        EXPECT_EQ(std::filesystem::exists(dir / (std::string(name) + ".buffers") / "0000" /
                                          "normals.pfm"),
                  std::string(name) == "weight.json")
            << name;
    }
}

TEST(TurntableCommandGLTest, WritesAnMp4WithFfmpeg) {
    if (std::system("command -v ffmpeg > /dev/null 2>&1") != 0) {
        GTEST_SKIP() << "ffmpeg is not installed (scripts/setup-deps.sh installs it)";
    }
    const test::TempDir dir;
    const auto result = runSubscan(
        with(with({"turntable"}, kScene), {"-o", (dir / "spin.mp4").string(), "--frames", "4"}));
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const std::string video = test::fileBytes(dir / "spin.mp4");
    ASSERT_GT(video.size(), 8u);
    EXPECT_EQ(video.substr(4, 4), "ftyp");  // an ISO media file
    // Nothing left beside it: the frames' folder and the partial file are gone.
    int entries = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path())) {
        ++entries;
    }
    EXPECT_EQ(entries, 1);

    // The extension in capitals is an MP4 too, not a folder of that name.
    const auto capitals = runSubscan(
        with(with({"turntable"}, kScene), {"-o", (dir / "SPIN.MP4").string(), "--frames", "2"}));
    ASSERT_EQ(capitals.exitCode, 0) << capitals.err;
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / "SPIN.MP4"));
}

/// Starts an endless turntable of `output` (and `more` options), sends it `signal` (a
/// terminal's Ctrl-C unless named) once `written` (a shell glob) matches a file, and returns its
/// exit status and stderr.
test::CommandResult interruptTurntable(const std::filesystem::path& output,
                                       const std::string& written, const std::string& more = "",
                                       const std::string& signal = "INT") {
    const test::TempDir capture;
    const std::string command = fmt::format(
        "SUBSCAN_GL_DEBUG=1 '{}' turntable synthetic:sphere?points=4000 --mode surface "
        "--width 64 --height 48 --frames 100000 -o '{}' {} 2> '{}' & pid=$!; "
        "for i in $(seq 600); do ls -d {} > /dev/null 2>&1 && break; sleep 0.1; done; "
        "kill -{} $pid; wait $pid",
        test::subscanExecutable(), output.string(), more, (capture / "err").string(), written,
        signal);
    test::CommandResult run = test::runProgram("/bin/sh", {"-c", command});
    run.err = test::fileBytes(capture / "err");
    return run;
}

TEST(TurntableCommandGLTest, CtrlCLeavesNoFramesBehind) {
    if (std::system("command -v ffmpeg > /dev/null 2>&1") != 0) {
        GTEST_SKIP() << "ffmpeg is not installed (scripts/setup-deps.sh installs it)";
    }
    // A terminal's Ctrl-C while the frames are rendered: they lay in a hidden folder beside the
    // video, which used to stay, with every frame so far. Sent once that folder holds a frame.
    const test::TempDir dir;
    const auto run =
        interruptTurntable(dir / "spin.mp4", (dir / ".spin.mp4.frames-*/0000.png").string());
    EXPECT_EQ(run.exitCode, 130) << run.err;  // the shell's status for Ctrl-C (it was 1)
    EXPECT_EQ(run.err, "subscan: " + (dir / "spin.mp4").string() +
                           ": interrupted; no video written, and what was there is left as it "
                           "was\n");
    EXPECT_EQ(test::folderEntries(dir.path()), std::vector<std::string>{});
}

TEST(TurntableCommandGLTest, CtrlCLeavesAFolderAsItWas) {
    // Frames were written in place and the earlier turntable's beyond them removed only at the
    // end: Ctrl-C left this run's first frames beside the earlier run's later ones, a sequence
    // that looked whole.
    const test::TempDir dir;
    const auto earlier = runSubscan(
        with(with({"turntable"}, kScene), {"-o", (dir / "frames").string(), "--frames", "3",
                                           "--export-buffers", (dir / "buffers").string()}));
    ASSERT_EQ(earlier.exitCode, 0) << earlier.err;
    std::vector<std::string> frames;
    for (const std::string& name : test::folderEntries(dir / "frames")) {
        frames.push_back(test::fileBytes(dir / "frames" / name));
    }
    const std::string depth = test::fileBytes(dir / "buffers" / "0002" / "depth.pfm");
    const auto run =
        interruptTurntable(dir / "frames", (dir / "frames" / ".frames-*/0003.png").string(),
                           "--export-buffers '" + (dir / "buffers").string() + "'");
    EXPECT_EQ(run.exitCode, 130) << run.err;
    EXPECT_EQ(run.err, "subscan: " + (dir / "frames").string() +
                           ": interrupted; no frames or buffers written, and what was there is "
                           "left as it was\n");
    EXPECT_EQ(test::folderEntries(dir / "buffers"),
              (std::vector<std::string>{"0000", "0001", "0002"}));
    EXPECT_EQ(test::fileBytes(dir / "buffers" / "0002" / "depth.pfm"), depth);
    ASSERT_EQ(test::folderEntries(dir / "frames"),
              (std::vector<std::string>{"0000.png", "0001.png", "0002.png"}));
    for (int index = 0; index < 3; ++index) {
        EXPECT_EQ(test::fileBytes(dir / "frames" / fmt::format("{:04}.png", index)),
                  frames[static_cast<std::size_t>(index)])
            << index;
    }
    // A folder the interrupted run made is gone with its frames.
    const auto fresh =
        interruptTurntable(dir / "new", (dir / "new" / ".frames-*/0000.png").string());
    EXPECT_EQ(fresh.exitCode, 130) << fresh.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "new"));
}

TEST(TurntableCommandGLTest, ALaterTurntableRemovesTheStagingFoldersOfAKilledOne) {
    // kill -9 (or a second Ctrl-C) leaves the hidden staging folders: the next turntable into
    // that --export-buffers folder refused it as someone else's files, and the frames' folder
    // kept the killed run's frames hidden in it.
    const test::TempDir dir;
    const auto frames = dir / "frames";
    const auto exported = dir / "buffers";
    const auto killed =
        interruptTurntable(frames, (exported / ".buffers-*/0001/camera.json").string(),
                           "--export-buffers '" + exported.string() + "'", "KILL");
    EXPECT_EQ(killed.exitCode, 128 + SIGKILL) << killed.err;
    const std::vector<std::string> leftFrames = test::folderEntries(frames);
    const std::vector<std::string> leftBuffers = test::folderEntries(exported);
    ASSERT_EQ(leftFrames.size(), 1u);
    ASSERT_EQ(leftBuffers.size(), 1u);
    ASSERT_THAT(leftFrames[0], ::testing::StartsWith(".frames-"));
    ASSERT_THAT(leftBuffers[0], ::testing::StartsWith(".buffers-"));

    const auto turntable = [&] {
        return runSubscan(
            with(with({"turntable"}, kScene), {"-o", frames.string(), "--frames", "2", "--warmup",
                                               "1", "--export-buffers", exported.string()}));
    };
    const auto later = turntable();
    ASSERT_EQ(later.exitCode, 0) << later.err;
    for (const auto& left : {frames / leftFrames[0], exported / leftBuffers[0]}) {
        EXPECT_THAT(later.err, HasSubstr("subscan: removed " + left.string() +
                                         ", which a killed turntable "
                                         "left\n"));
    }
    EXPECT_EQ(test::folderEntries(frames), (std::vector<std::string>{"0000.png", "0001.png"}));
    EXPECT_EQ(test::folderEntries(exported), (std::vector<std::string>{"0000", "0001"}));

    // Only a folder named exactly as one, of a process that has ended, holding only a
    // turntable's files: anything else is left as it is, and the export folder refused.
    std::filesystem::create_directories(exported / leftBuffers[0] / "0000");
    const auto notes = dir.write("buffers/" + leftBuffers[0] + "/0000/notes.txt", "mine");
    const auto lookalike = frames / (leftFrames[0] + "x");
    const auto running = frames / fmt::format(".frames-{}", ::getpid());
    for (const auto& folder : {lookalike, running}) {
        std::filesystem::create_directories(folder);
        std::filesystem::copy_file(frames / "0000.png", folder / "0000.png");
    }
    const auto refused = turntable();
    EXPECT_EQ(refused.exitCode, 1);
    EXPECT_THAT(refused.err, HasSubstr((exported / leftBuffers[0]).string() +
                                       ": --export-buffers replaces the files of an earlier "
                                       "export in its folder"));
    EXPECT_THAT(refused.err, ::testing::Not(HasSubstr("removed")));
    EXPECT_EQ(test::fileBytes(notes), "mine");
    EXPECT_EQ(test::folderEntries(lookalike), std::vector<std::string>{"0000.png"});
    EXPECT_EQ(test::folderEntries(running), std::vector<std::string>{"0000.png"});
}

/// The PID of a process that has ended (another gets it only once the kernel's PIDs wrap).
pid_t endedProcessId() {
    const pid_t child = ::fork();
    if (child == 0) {
        ::_exit(0);
    }
    ::waitpid(child, nullptr, 0);
    return child;
}

TEST(TurntableCommandGLTest, AKilledTurntablesPartialFramesGoButAnInputStays) {
    // Killed while writing, a turntable leaves a frame half written (.NAME.xxxxxxxx.tmp) beside
    // its finished ones: still its own. A staging folder that holds the scan being rendered (a
    // PLY under a frame's name) is never removed.
    const test::TempDir dir;
    const auto frames = dir / "frames";
    const auto killed = frames / fmt::format(".frames-{}", endedProcessId());
    const auto holdingInput = frames / fmt::format(".frames-{}", endedProcessId());
    std::filesystem::create_directories(killed);
    std::filesystem::create_directories(holdingInput);
    dir.write("frames/" + killed.filename().string() + "/0000.png", "a frame");
    dir.write("frames/" + killed.filename().string() + "/.0001.png.0123abcd.tmp", "half");
    const std::string ply =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    const auto input = dir.write("frames/" + holdingInput.filename().string() + "/0000.png", ply);
    const auto later = runSubscan({"turntable", input.string(), "-o", frames.string(), "--frames",
                                   "2", "--warmup", "1", "--width", "40", "--height", "32"});
    ASSERT_EQ(later.exitCode, 0) << later.err;
    EXPECT_FALSE(std::filesystem::exists(killed));
    EXPECT_THAT(later.err, HasSubstr("subscan: removed " + killed.string()));
    EXPECT_EQ(test::fileBytes(input), ply);
    EXPECT_THAT(later.err, ::testing::Not(HasSubstr(holdingInput.string())));
}

TEST(TurntableCommandGLTest, AFolderHoldsThisSequenceAlone) {
    // A shorter turntable into the folder of a longer one: its frames beyond went unnoticed
    // into whatever read the folder next (ffmpeg -i %04d.png mixed the two runs).
    const test::TempDir dir;
    const auto longer = runSubscan(
        with(with({"turntable"}, kScene), {"-o", (dir / "frames").string(), "--frames", "4"}));
    ASSERT_EQ(longer.exitCode, 0) << longer.err;
    const std::filesystem::path other = dir.write("frames/notes.txt", "mine");
    const auto shorter = runSubscan(
        with(with({"turntable"}, kScene), {"-o", (dir / "frames").string(), "--frames", "2"}));
    ASSERT_EQ(shorter.exitCode, 0) << shorter.err;
    EXPECT_THAT(shorter.err, HasSubstr("removed 2 frames of an earlier turntable"));
    EXPECT_TRUE(std::filesystem::exists(dir / "frames" / "0001.png"));
    EXPECT_FALSE(std::filesystem::exists(dir / "frames" / "0002.png"));
    EXPECT_FALSE(std::filesystem::exists(dir / "frames" / "0003.png"));
    EXPECT_EQ(test::fileBytes(other), "mine");  // nothing else is touched
}

TEST(TurntableCommandGLTest, AReusedExportFolderHoldsThisTurntableAlone) {
    // Into the folder of a longer turntable of another mode: its frame folders beyond this
    // one's and its buffers this mode does not write stayed beside this turntable's.
    const test::TempDir dir;
    const auto exported = dir / "buffers";
    auto turntable = [&](int frames, const std::string& mode) {
        return runSubscan({"turntable", "synthetic:sphere?points=4000", "--width", "40", "--height",
                           "32", "--warmup", "1", "--mode", mode, "--frames",
                           std::to_string(frames), "-o", (dir / mode).string(), "--export-buffers",
                           exported.string()});
    };
    const auto longer = turntable(3, "surface");
    ASSERT_EQ(longer.exitCode, 0) << longer.err;
    EXPECT_TRUE(std::filesystem::exists(exported / "0000" / "normals.pfm"));
    const auto shorter = turntable(2, "points");
    ASSERT_EQ(shorter.exitCode, 0) << shorter.err;
    EXPECT_THAT(shorter.err, HasSubstr("removed the buffers of 1 frames of an earlier turntable"));
    EXPECT_EQ(test::folderEntries(exported), (std::vector<std::string>{"0000", "0001"}));
    for (const char* frame : {"0000", "0001"}) {
        EXPECT_EQ(test::folderEntries(exported / frame),
                  (std::vector<std::string>{"camera.json", "color.png", "depth.pfm"}))
            << frame;
    }

    // Anything else there might be someone's: refused before anything is written.
    const auto notes = dir.write("buffers/0001/notes.txt", "mine");
    const auto refused = turntable(1, "surface");
    EXPECT_EQ(refused.exitCode, 1);
    EXPECT_THAT(refused.err, HasSubstr(notes.string() + ": --export-buffers replaces the files "
                                                        "of an earlier export in its folder"));
    EXPECT_EQ(test::fileBytes(notes), "mine");
    EXPECT_EQ(test::folderEntries(exported / "0001"),
              (std::vector<std::string>{"camera.json", "color.png", "depth.pfm", "notes.txt"}));
}

TEST(TurntableCommandGLTest, TurnsAStreamedSurveyWithinItsBudget) {
    // The lone star's COPC file streamed: one set of nodes for every frame within the budget;
    // each frame shows the survey. --lod off loads it whole instead, and what cannot be
    // streamed is refused under --lod on.
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const test::TempDir folder;
    const std::string copc = (data / "lone_star.copc.laz").string();
    const auto turn = [&](const std::string& name, const std::vector<std::string>& extra) {
        std::vector<std::string> arguments{"turntable", copc,
                                           "--mode",    "surface",
                                           "--frames",  "3",
                                           "--width",   "96",
                                           "--height",  "72",
                                           "--warmup",  "1",
                                           "-o",        (folder / name).string()};
        arguments.insert(arguments.end(), extra.begin(), extra.end());
        const test::CommandResult result = runSubscan(arguments);
        EXPECT_EQ(result.exitCode, 0) << result.err;
        std::vector<Image8> frames;
        for (int index = 0; index < 3; ++index) {
            frames.push_back(readPng(folder / name / fmt::format("{:04}.png", index)));
        }
        return frames;
    };
    const std::vector<Image8> streamed = turn("streamed", {"--point-budget", "50000"});
    const std::vector<Image8> whole = turn("whole", {"--lod", "off"});
    for (int index = 0; index < 3; ++index) {
        const Image8& frame = streamed[static_cast<std::size_t>(index)];
        const Image8& reference = whole[static_cast<std::size_t>(index)];
        std::size_t covered = 0, coveredWhole = 0;
        for (std::size_t i = 0; i < frame.pixels.size(); i += 4) {
            covered += frame.pixels[i] != frame.pixels[0] || frame.pixels[i + 1] != frame.pixels[1];
            coveredWhole += reference.pixels[i] != reference.pixels[0] ||
                            reference.pixels[i + 1] != reference.pixels[1];
        }
        // The same survey from the same cameras (it covers 9 % of these small frames): a
        // surface as large as the whole file's, a tenth of the points closing into it.
        EXPECT_GT(coveredWhole, frame.pixels.size() / 4 / 20) << index;
        EXPECT_NEAR(static_cast<double>(covered), static_cast<double>(coveredWhole),
                    0.1 * static_cast<double>(coveredWhole))
            << index;
    }
    const test::CommandResult refused =
        runSubscan({"turntable", (data / "bun_zipper_res4.ply").string(), "--lod", "on", "--frames",
                    "2", "-o", (folder / "refused").string()});
    EXPECT_NE(refused.exitCode, 0);
    EXPECT_THAT(refused.err, ::testing::HasSubstr("bun_zipper_res4.ply"));
}

TEST(TurntableCommandGLTest, RefusesWhatItCannotDoWithOneSentence) {
    const test::TempDir dir;
    // No ffmpeg on PATH: an error naming the output and the package, no file.
    const auto noFfmpeg = runSubscan(
        with(with({"turntable"}, kScene), {"-o", (dir / "spin.mp4").string(), "--frames", "2"}),
        {"PATH=" + dir.path().string()});
    EXPECT_EQ(noFfmpeg.exitCode, 1);
    EXPECT_THAT(noFfmpeg.err, HasSubstr("ffmpeg is not installed"));
    EXPECT_FALSE(std::filesystem::exists(dir / "spin.mp4"));

    // A picture's or another video format's name: refused, not made a folder of that name.
    for (const char* name : {"spin.gif", "spin.mov", "still.PNG"}) {
        const auto media = runSubscan(
            with(with({"turntable"}, kScene), {"-o", (dir / name).string(), "--frames", "2"}));
        EXPECT_EQ(media.exitCode, 1) << name;
        EXPECT_THAT(media.err, HasSubstr("turntable writes an MP4 video")) << name;
        EXPECT_FALSE(std::filesystem::exists(dir / name)) << name;
    }

    // Over its own input.
    const std::filesystem::path scan = dir.write("scan.xyz", "0 0 0\n1 0 0\n0 1 0\n");
    const auto overInput = runSubscan({"turntable", scan.string(), "-o", scan.string()});
    EXPECT_EQ(overInput.exitCode, 1);
    EXPECT_THAT(overInput.err, HasSubstr("refusing to write"));
    EXPECT_EQ(test::fileBytes(scan), "0 0 0\n1 0 0\n0 1 0\n");

    // Over an input in the frames' folder under a frame's name (a PLY, known by its content).
    std::filesystem::create_directory(dir / "frames");
    const std::string ply =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    const std::filesystem::path frameNamed = dir.write("frames/0001.png", ply);
    const auto overFrame = runSubscan(
        {"turntable", frameNamed.string(), "-o", (dir / "frames").string(), "--frames", "3"});
    EXPECT_EQ(overFrame.exitCode, 1);
    EXPECT_THAT(overFrame.err, HasSubstr("refusing to write a frame over the input scan"));
    EXPECT_EQ(test::fileBytes(frameNamed), ply);

    // --save-settings over the settings file it reads.
    const std::filesystem::path settings = dir.write("settings.json", "{}");
    const auto overSettings = runSubscan(
        with(with({"render"}, kScene), {"-o", (dir / "x.png").string(), "--settings",
                                        settings.string(), "--save-settings", settings.string()}));
    EXPECT_EQ(overSettings.exitCode, 1);
    EXPECT_THAT(overSettings.err, HasSubstr("refusing to write the settings"));
    EXPECT_EQ(test::fileBytes(settings), "{}");
}

}  // namespace
}  // namespace subscan
