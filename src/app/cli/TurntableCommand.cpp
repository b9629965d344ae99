#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <glm/ext/matrix_transform.hpp>

#include "app/ProgressBar.h"
#include "app/cli/BufferExport.h"
#include "app/cli/CommandSupport.h"
#include "app/cli/Commands.h"
#include "app/cli/FrameOptions.h"
#include "app/cli/InterruptWatcher.h"
#include "core/Error.h"
#include "io/AtomicFile.h"
#include "io/Image.h"
#include "io/TextParsing.h"
#include "lod/NodeSelection.h"
#include "render/Renderer.h"

extern char** environ;

namespace subscan::cli {

namespace {

struct TurntableOptions {
    FrameOptions frame;
    std::string output;  // OUT.mp4, or a folder of PNGs
    int frames = 120;
    double degrees = 360.0;
    int fps = 30;
    int warmup = 16;  // still frames at the first pose before the first written one
    std::string exportDirectory;
};

bool writesVideo(const std::filesystem::path& output) {
    return asciiLowercase(output.extension().string()) == ".mp4";
}

/// Refuses an output named as a picture or a video turntable cannot write: it would have become
/// a folder of that name.
void checkOutputName(const std::filesystem::path& output) {
    const std::string extension = asciiLowercase(output.extension().string());
    for (const char* media :
         {".mov", ".gif", ".webm", ".mkv", ".avi", ".m4v", ".png", ".jpg", ".jpeg", ".apng"}) {
        if (extension == media) {
            throw Error(fmt::format(
                "{}: turntable writes an MP4 video (-o NAME.mp4) or a folder of numbered PNGs, "
                "not {} files",
                output.string(), extension));
        }
    }
}

/// Frame `index`'s name: 0000.png, 0001.png, ... with `extension` ".png", and its buffers'
/// folder's 0000, 0001, ... with none.
std::string frameName(int index, std::string_view extension) {
    return fmt::format("{:04}{}", index, extension);
}

/// The index of the frame named `name`, where frameName gives that name; else nullopt.
std::optional<int> frameIndexOf(const std::string& name, std::string_view extension) {
    if (!name.ends_with(extension)) {
        return std::nullopt;
    }
    const std::string_view digits(name.data(), name.size() - extension.size());
    int index = -1;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), index);
    if (error != std::errc() || end != digits.data() + digits.size() || index < 0 ||
        frameName(index, extension) != name) {
        return std::nullopt;
    }
    return index;
}

/// The paths of the frames named as frameName names them in `folder` (none where it does not
/// exist).
std::vector<std::filesystem::path> framesIn(const std::filesystem::path& folder,
                                            std::string_view extension) {
    std::vector<std::filesystem::path> frames;
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
        if (frameIndexOf(entry.path().filename().string(), extension)) {
            frames.push_back(entry.path());
        }
    }
    return frames;
}

/// Puts the first `frames` frames of this run from `staging` into `folder` in place of an
/// earlier turntable's, which `removeEarlier` removes, as it does that one's frames beyond
/// them, so that the folder holds this sequence alone; returns how many were beyond.
int replaceFrames(const std::filesystem::path& staging, const std::filesystem::path& folder,
                  int frames, std::string_view extension,
                  const std::function<void(const std::filesystem::path&)>& removeEarlier) {
    for (int index = 0; index < frames; ++index) {
        const std::filesystem::path target = folder / frameName(index, extension);
        std::error_code error;
        if (std::filesystem::exists(std::filesystem::symlink_status(target))) {
            removeEarlier(target);  // a folder cannot be renamed over
        }
        std::filesystem::rename(staging / target.filename(), target, error);
        if (error) {
            throw Error(fmt::format("{}: cannot put this frame in place: {}", target.string(),
                                    error.message()));
        }
    }
    int removed = 0;
    for (const std::filesystem::path& earlier : framesIn(folder, extension)) {
        if (*frameIndexOf(earlier.filename().string(), extension) >= frames) {
            removeEarlier(earlier);
            ++removed;
        }
    }
    return removed;
}

/// Throws subscan::Error where the folder of --export-buffers holds more than an earlier
/// turntable's frame folders, which this run replaces, and this run's other outputs, or where
/// replacing them would write over or remove an input.
void checkExportFolders(const TurntableOptions& options) {
    const FrameOptions& frame = options.frame;
    const std::filesystem::path folder = options.exportDirectory;
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
        const std::string name = entry.path().filename().string();
        if (entry.is_directory() && frameIndexOf(name, "")) {
            checkExportFolder(frame, entry.path());
        } else if (!sameFile(entry.path(), options.output) &&
                   !sameFile(entry.path(), frame.saveSettingsFile) &&
                   !(frameIndexOf(name, ".png") && sameFile(folder, options.output))) {
            throw notAnExport(entry.path());
        }
    }
}

/// The ffmpeg on PATH, or nullopt.
std::optional<std::filesystem::path> findFfmpeg() {
    const char* path = std::getenv("PATH");
    std::string_view directories = path ? path : "/usr/bin:/bin";
    while (!directories.empty()) {
        const std::size_t colon = directories.find(':');
        const std::filesystem::path candidate =
            std::filesystem::path(directories.substr(0, colon)) / "ffmpeg";
        if (::access(candidate.c_str(), X_OK) == 0) {
            return candidate;
        }
        directories = colon == std::string_view::npos ? "" : directories.substr(colon + 1);
    }
    return std::nullopt;
}

/// Runs ffmpeg on the numbered PNGs in `frames` into `video` (H.264, yuv420p, even sizes);
/// throws subscan::Error with its exit status.
void encodeVideo(const std::filesystem::path& ffmpeg, const std::filesystem::path& frames,
                 const std::filesystem::path& video, int fps,
                 const std::atomic<bool>& interrupted) {
    // -nostdin: ffmpeg would otherwise read (and, in the background, stop on) the terminal.
    const std::vector<std::string> arguments = {
        ffmpeg.string(), "-nostdin", "-y", "-loglevel", "error", "-framerate", std::to_string(fps),
        "-i", (frames / "%04d.png").string(),
        // yuv420p, which every player reads, needs even sizes: pad by a pixel when odd.
        "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p",
        "-movflags", "+faststart", "-f", "mp4", video.string()};
    std::vector<char*> argv;
    for (const std::string& argument : arguments) {
        argv.push_back(const_cast<char*>(argument.c_str()));
    }
    argv.push_back(nullptr);
    // ffmpeg takes Ctrl-C as a terminal sends it to both, though this process blocks it
    // (InterruptWatcher): the child starts with no signal blocked.
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    sigset_t none;
    sigemptyset(&none);
    posix_spawnattr_setsigmask(&attributes, &none);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK);
    pid_t child = 0;
    const int spawned = posix_spawn(&child, argv[0], nullptr, &attributes, argv.data(), environ);
    posix_spawnattr_destroy(&attributes);
    if (spawned != 0) {
        throw Error(fmt::format("{}: cannot run {}", video.string(), ffmpeg.string()));
    }
    // Waited for in steps, so that an interrupt meant for this process alone stops ffmpeg too
    // instead of waiting for the whole video.
    int status = 0;
    pid_t waited = 0;
    bool stopped = false;
    for (;;) {
        waited = waitpid(child, &status, WNOHANG);
        if (waited == child || (waited == -1 && errno != EINTR)) {
            break;
        }
        if (interrupted && !stopped) {
            ::kill(child, SIGTERM);
            stopped = true;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    if (waited != child || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        throw Error(fmt::format("{}: ffmpeg failed to encode the frames (exit status {})",
                                video.string(), WIFEXITED(status) ? WEXITSTATUS(status) : -1));
    }
}

void createFolder(const std::filesystem::path& folder, std::string_view what) {
    std::error_code error;
    std::filesystem::create_directories(folder, error);
    if (error || !std::filesystem::is_directory(folder)) {
        throw Error(fmt::format("{}: cannot create the {} folder{}", folder.string(), what,
                                error ? ": " + error.message() : ""));
    }
}

/// The name of the hidden folder StagingFolder makes for process `pid`.
std::string stagingName(std::string_view prefix, std::string_view what, pid_t pid) {
    return fmt::format(".{}{}-{}", prefix, what, pid);
}

/// The process whose staging folder `name` is, where stagingName gives `name` for `prefix` and
/// `what`; else nullopt.
std::optional<pid_t> stagingOwner(std::string_view name, std::string_view prefix,
                                  std::string_view what) {
    const std::size_t dash = name.rfind('-');
    if (dash == std::string_view::npos) {
        return std::nullopt;
    }
    const std::string_view digits = name.substr(dash + 1);
    pid_t pid = 0;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), pid);
    if (error != std::errc() || end != digits.data() + digits.size() || pid <= 0 ||
        stagingName(prefix, what, pid) != name) {
        return std::nullopt;
    }
    return pid;
}

/// What a staging folder holds: numbered PNGs, or numbered folders of buffer files.
enum class Staged { Frames, Buffers };

std::string_view stagedName(Staged staged) {
    return staged == Staged::Frames ? "frames" : "buffers";
}

/// The entries of `folder` where each has the type `type` (links are none of theirs) and, for
/// files, a name `isOurs` takes, or is a partial file of one (its writer killed); else nullopt.
std::optional<std::vector<std::filesystem::path>> entriesIfOurs(
    const std::filesystem::path& folder, std::filesystem::file_type type,
    const std::function<bool(const std::string&)>& isOurs) {
    std::error_code error;
    const std::filesystem::directory_iterator entries(folder, error);
    if (error) {
        return std::nullopt;
    }
    std::vector<std::filesystem::path> ours;
    for (const auto& entry : entries) {
        const std::string name = entry.path().filename().string();
        const std::optional<std::string> partialOf = atomicWriteTargetOf(name);
        if (entry.symlink_status(error).type() != type ||
            !isOurs(partialOf && type == std::filesystem::file_type::regular ? *partialOf : name)) {
            return std::nullopt;
        }
        ours.push_back(entry.path());
    }
    return ours;
}

/// What the staging folder `path` holds where a turntable killed while it ran (a second Ctrl-C,
/// kill -9) left it: named by stagingName, of a process that no longer runs, and holding only
/// what a turntable stages there, none of it an input. Files come first, then frame folders,
/// then `path`: an order they can be removed in one by one. Else nullopt.
std::optional<std::vector<std::filesystem::path>> leftStagingFolder(
    const std::filesystem::path& path, std::string_view prefix, Staged staged,
    const FrameOptions& frame) {
    const std::optional<pid_t> owner =
        stagingOwner(path.filename().string(), prefix, stagedName(staged));
    // kill(pid, 0) says whether the process exists (EPERM: as someone else's), which may be
    // another turntable staging its frames. This process has made none yet.
    if (!owner || (*owner != ::getpid() && (::kill(*owner, 0) == 0 || errno == EPERM))) {
        return std::nullopt;
    }
    std::error_code error;
    if (std::filesystem::symlink_status(path, error).type() !=
        std::filesystem::file_type::directory) {
        return std::nullopt;
    }
    using std::filesystem::file_type;
    std::vector<std::filesystem::path> files;
    std::vector<std::filesystem::path> folders;
    if (staged == Staged::Frames) {
        auto frames = entriesIfOurs(path, file_type::regular, [](const std::string& name) {
            return frameIndexOf(name, ".png").has_value();
        });
        if (!frames) {
            return std::nullopt;
        }
        files = std::move(*frames);
    } else {
        auto frameFolders = entriesIfOurs(path, file_type::directory, [](const std::string& name) {
            return frameIndexOf(name, "").has_value();
        });
        if (!frameFolders) {
            return std::nullopt;
        }
        for (const std::filesystem::path& frameFolder : *frameFolders) {
            const auto buffers =
                entriesIfOurs(frameFolder, file_type::regular,
                              [](const std::string& name) { return isBufferFile(name); });
            if (!buffers) {
                return std::nullopt;
            }
            files.insert(files.end(), buffers->begin(), buffers->end());
        }
        folders = std::move(*frameFolders);
    }
    if (std::any_of(files.begin(), files.end(),
                    [&](const std::filesystem::path& file) { return frame.isInput(file); })) {
        return std::nullopt;
    }
    files.insert(files.end(), folders.begin(), folders.end());
    files.push_back(path);
    return files;
}

/// Removes the staging folders in `folder` that killed turntables left there (a later export
/// into the folder refused them as someone else's files), and says so; anything else, and what
/// cannot be removed, stays.
void removeLeftStagingFolders(const std::filesystem::path& folder, std::string_view prefix,
                              Staged staged, const FrameOptions& frame) {
    std::vector<std::filesystem::path> entries;
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator(
             folder.empty() ? std::filesystem::path(".") : folder, error)) {
        entries.push_back(entry.path());
    }
    for (const std::filesystem::path& path : entries) {
        const auto left = leftStagingFolder(path, prefix, staged, frame);
        if (!left) {
            continue;
        }
        // A folder that cannot be removed (another user's, in a shared folder) stays: it is in
        // no one's way but an export into this folder, which then refuses it and says why.
        std::error_code failed;
        for (const std::filesystem::path& item : *left) {
            if (std::filesystem::remove(item, failed); failed) {
                fmt::print(stderr,
                           "subscan: warning: {}: cannot remove what a killed turntable left "
                           "({}); it stays\n",
                           item.string(), failed.message());
                break;
            }
        }
        if (!failed) {
            fmt::print(stderr, "subscan: removed {}, which a killed turntable left\n",
                       path.string());
        }
    }
}

/// A hidden folder in `folder` (made if missing) that holds a run's frames until they are
/// complete, removed with what is left in it when the run ends, and `folder` too where the run
/// made it and put nothing else there: an interrupted or failed turntable leaves none of its
/// output.
class StagingFolder {
  public:
    /// stagedName(staged) names it, after `prefix`, and the folder in errors.
    StagingFolder(const std::filesystem::path& folder, Staged staged, std::string_view prefix = "")
        : folder_(folder),
          madeFolder_(!folder.empty() && !std::filesystem::exists(folder)),
          path_(folder / stagingName(prefix, stagedName(staged), ::getpid())) {
        if (!folder.empty()) {
            // Said of the folder given, not of the hidden one.
            createFolder(folder, stagedName(staged));
        }
        createFolder(path_, stagedName(staged));
    }
    ~StagingFolder() {
        std::error_code ignored;
        std::filesystem::remove_all(path_, ignored);
        if (madeFolder_) {
            std::filesystem::remove(folder_, ignored);  // a folder that is not empty stays
        }
    }
    StagingFolder(const StagingFolder&) = delete;
    StagingFolder& operator=(const StagingFolder&) = delete;
    const std::filesystem::path& path() const { return path_; }

  private:
    std::filesystem::path folder_;
    bool madeFolder_;
    std::filesystem::path path_;
};

int runTurntable(const TurntableOptions& options) {
    // Before any thread starts (the GL driver's), so that every thread blocks the signals.
    InterruptWatcher interrupts;
    const FrameOptions& frame = options.frame;
    const std::filesystem::path output = options.output;
    checkOutputName(output);
    frame.refuseToOverwriteInputs(output, "the turntable");
    frame.refuseToOverwriteInputs(frame.saveSettingsFile, "the settings");
    const bool video = writesVideo(output);
    if (video) {
        requireOutputFolder(output);
    }
    requireOutputFolder(frame.saveSettingsFile);
    // Nor over (or removing, as an earlier turntable's) an input that lies in the frames'
    // folder under a frame's name.
    for (const std::filesystem::path& earlier :
         video ? std::vector<std::filesystem::path>() : framesIn(output, ".png")) {
        frame.refuseToOverwriteInputs(earlier, "a frame");
    }
    std::optional<std::filesystem::path> ffmpeg;
    if (video) {
        ffmpeg = findFfmpeg();
        if (!ffmpeg) {
            throw Error(fmt::format(
                "{}: ffmpeg is not installed (Debian package ffmpeg); give -o a folder to get "
                "numbered PNGs instead",
                output.string()));
        }
    }
    // Before checkExportFolders, which would refuse them as someone else's files.
    if (video) {
        removeLeftStagingFolders(output.parent_path(), output.filename().string() + ".",
                                 Staged::Frames, frame);
    } else {
        removeLeftStagingFolders(output, "", Staged::Frames, frame);
    }
    if (!options.exportDirectory.empty()) {
        removeLeftStagingFolders(options.exportDirectory, "", Staged::Buffers, frame);
        checkExportFolders(options);
    }
    RenderSettings settings = frame.settings();
    settings.temporal.enabled = true;
    const bool filtered = filtersTemporally(settings);

    const std::unique_ptr<GlContext> context = frame.context();
    // A streamed survey is framed by its top levels; then one set of nodes for every frame
    // (the ones any frame shows, within the budget), so that nothing pops as it turns.
    const std::unique_ptr<lod::NodeSource> streamed =
        lod::openStreamed(frame.source, settings.streaming.lod);
    LoadedScan scan =
        streamed ? lod::loadStreamedOverview(*streamed) : loadScanForCommand(frame.source);
    // The bounding sphere frames every yaw alike; the box's fit holds for the first one only.
    const Camera first = frame.camera(scan, Framing::Sphere);
    // Each frame turns the scene about the up axis through the bounds' middle: the eye's yaw
    // grows by degrees / frames, as --yaw would.
    const glm::dvec3 centre = scan.cloud.bounds.center();
    const glm::dvec3 axis = orbitFrame(frame.upAxis(scan)).up;
    auto cameraAt = [&](int index) {
        const double angle = glm::radians(options.degrees * index / options.frames);
        Camera camera = first;
        camera.view = first.view * glm::translate(glm::dmat4(1.0), centre) *
                      glm::rotate(glm::dmat4(1.0), -angle, axis) *
                      glm::translate(glm::dmat4(1.0), -centre);
        return camera;
    };

    if (streamed) {
        std::vector<Camera> cameras;
        for (int index = 0; index < options.frames; ++index) {
            cameras.push_back(cameraAt(index));
        }
        scan = loadStreamedView(
            *streamed, cameras,
            lod::pointBudgetFor(settings.streaming.pointBudget, context->capabilities().software));
    }
    frame.applyColoring(scan);
    // `scan` outlives the renderer unchanged: the GPU may read its points in place.
    Renderer renderer(*context, scan.cloud, estimatePointSpacing(scan.cloud, scan.levelSpacing), 0,
                      PointMemory::Borrow);
    renderer.prepareNormals(scan.cloud, streamed ? streamedNormals(settings.surface.normals)
                                                 : settings.surface.normals);
    // From the frames' folder on an interrupt stops at the next frame, which cleans up.
    interrupts.defer();
    // A video's frames beside it, a folder's in it (so that they move in by renaming).
    const StagingFolder frames = video ? StagingFolder(output.parent_path(), Staged::Frames,
                                                       output.filename().string() + ".")
                                       : StagingFolder(output, Staged::Frames);
    std::optional<StagingFolder> buffers;
    if (!options.exportDirectory.empty()) {
        buffers.emplace(options.exportDirectory, Staged::Buffers);
    }
    const FrameOutputs outputs =
        options.exportDirectory.empty() ? FrameOutputs::Picture : FrameOutputs::Everything;
    // The first written frame is already converged: the mean of `warmup` frames, itself
    // included.
    for (int still = 1; filtered && still < options.warmup; ++still) {
        renderer.render(first, settings, outputs);
    }
    ProgressBar bar("turntable", options.frames > 1);
    auto stopIfInterrupted = [&] {
        if (interrupts.interrupted()) {
            throw interrupts.stopped(fmt::format(
                "{}: interrupted; no {}{} written, and what was there is left as it was",
                output.string(), video ? "video" : "frames", buffers ? " or buffers" : ""));
        }
    };
    for (int index = 0; index < options.frames; ++index) {
        stopIfInterrupted();
        const Camera camera = cameraAt(index);
        renderer.render(camera, settings, outputs);
        const Image8 picture{camera.width, camera.height, 4, renderer.readImage()};
        context->throwOnErrors(fmt::format("while rendering frame {}", index));
        writePng(frames.path() / frameName(index, ".png"), picture);
        if (buffers) {
            exportBuffers(buffers->path() / frameName(index, ""), renderer, settings, camera);
        }
        bar.update((index + 1.0) / options.frames);
    }
    if (video) {
        // Encoded beside the output and renamed over it once complete; removed on failure.
        const std::filesystem::path partial =
            output.parent_path() / fmt::format(".{}.partial", output.filename().string());
        std::error_code error;
        try {
            encodeVideo(*ffmpeg, frames.path(), partial, options.fps, interrupts.interrupted());
            stopIfInterrupted();
            std::filesystem::rename(partial, output, error);
        } catch (const Error&) {
            std::filesystem::remove(partial, error);
            stopIfInterrupted();
            throw;
        }
        if (error) {
            std::filesystem::remove(partial, error);
            throw Error(
                fmt::format("{}: cannot write the video: {}", output.string(), error.message()));
        }
    } else {
        stopIfInterrupted();
        if (const int removed = replaceFrames(
                frames.path(), output, options.frames, ".png",
                [](const std::filesystem::path& earlier) {
                    removeEarlierOutput(earlier, "this frame of an earlier turntable");
                });
            removed > 0) {
            fmt::print(stderr, "subscan: removed {} frames of an earlier turntable from {}\n",
                       removed, output.string());
        }
    }
    if (buffers) {
        if (const int removed = replaceFrames(buffers->path(), options.exportDirectory,
                                              options.frames, "", removeExport);
            removed > 0) {
            fmt::print(
                stderr,
                "subscan: removed the buffers of {} frames of an earlier turntable from {}\n",
                removed, options.exportDirectory);
        }
    }
    frame.saveSettings(settings);
    return 0;
}

}  // namespace

Command addTurntableCommand(CLI::App& parent) {
    auto options = std::make_shared<TurntableOptions>();
    CLI::App* turntable = parent.add_subcommand(
        "turntable", "A turntable animation through the temporal filter (MP4 or numbered PNGs)");
    // A turntable of the surface unless --mode or the settings file names another mode.
    options->frame.add(*turntable, RenderMode::Surface);
    turntable
        ->add_option("-o,--output", options->output,
                     "OUT.mp4 (encoded by ffmpeg) or a folder for 0000.png, 0001.png, ...")
        ->required();
    turntable->add_option("--frames", options->frames, "Frames of the animation")
        ->check(CLI::Range(1, 100000));
    turntable->add_option("--degrees", options->degrees, "Degrees the scan turns in all")
        ->check(finiteNumber())
        ->check(CLI::Range(-36000.0, 36000.0));
    turntable->add_option("--fps", options->fps, "Frames per second of the video")
        ->check(CLI::Range(1, 240));
    turntable
        ->add_option("--warmup", options->warmup,
                     "Frames the temporal filter averages at the first pose for the first "
                     "frame (itself included)")
        ->check(CLI::Range(1, 2048));
    turntable->add_option("--export-buffers", options->exportDirectory,
                          "Directory for each frame's buffers: DIR/0000/, DIR/0001/, ... "
                          "(camera.json, depth.pfm, ...)");
    return {turntable, [options] { return runTurntable(*options); }};
}

}  // namespace subscan::cli
