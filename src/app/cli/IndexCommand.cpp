#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "app/ProgressBar.h"
#include "app/cli/CommandSupport.h"
#include "app/cli/Commands.h"
#include "app/cli/InterruptWatcher.h"
#include "core/Error.h"
#include "io/PointRecordSource.h"
#include "lod/CopcWriter.h"
#include "lod/OctreeIndexer.h"

namespace subscan::cli {

namespace {

/// The memory budget without --memory: measured peak RSS stays within it with room to spare
/// on the 24 GB machines this was built on (bench/README, "subscan index"), and it leaves a
/// laptop's memory to the rest of the system.
constexpr std::size_t kDefaultMemoryMegabytes = 1536;

struct IndexOptions {
    std::vector<std::string> sources;
    std::string output;
    unsigned threads = 0;
    std::size_t memoryMegabytes = kDefaultMemoryMegabytes;
    std::string temporaryDirectory;
};

void checkOutput(const IndexOptions& options) {
    const std::filesystem::path output(options.output);
    const std::string name = output.filename().string();
    if (name.size() < 9 || name.substr(name.size() - 9) != ".copc.laz") {
        throw Error(fmt::format("{}: the output of index is a COPC file: name it *.copc.laz",
                                options.output));
    }
    for (const std::string& source : options.sources) {
        if (sameFile(source, output)) {
            throw Error(
                fmt::format("{}: refusing to write the index over its input", options.output));
        }
    }
}

int runIndex(const IndexOptions& options) {
    checkOutput(options);
    const auto start = std::chrono::steady_clock::now();
    InterruptWatcher interrupts;
    // The indexer checks the flag from its first step and removes what it wrote.
    interrupts.defer();

    std::vector<std::unique_ptr<PointRecordSource>> sources;
    for (const std::string& path : options.sources) {
        sources.push_back(openPointRecordSource(path, options.threads));
    }
    std::unique_ptr<PointRecordSource> source = sources.size() == 1
                                                    ? std::move(sources.front())
                                                    : mergePointRecordSources(std::move(sources));
    const PointRecordSourceInfo& info = source->info();
    printSourceWarnings(info);

    lod::IndexSettings settings;
    settings.threads = options.threads;
    settings.memoryBytes = options.memoryMegabytes << 20;
    const std::filesystem::path output(options.output);
    settings.temporaryDirectory = options.temporaryDirectory.empty()
                                      ? std::filesystem::absolute(output).parent_path()
                                      : std::filesystem::path(options.temporaryDirectory);
    settings.cancelled = &interrupts.interrupted();
    ProgressBar bar("indexing", info.pointCount > 1'000'000);
    settings.progress = [&](double fraction, std::string_view phase) {
        bar.update(fraction, fmt::format("{}, {:.1f} M points", phase,
                                         static_cast<double>(info.pointCount) * 1e-6));
    };

    const lod::CopcFile written = [&] {
        try {
            return lod::writeCopc(*source, output, settings);
        } catch (const Error& error) {
            if (interrupts.interrupted()) {  // the indexer's own sentence says what it left
                throw interrupts.stopped(fmt::format("{}: {}", options.output, error.what()));
            }
            throw;
        }
    }();
    const lod::IndexSummary& summary = written.summary;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    fmt::print(
        "{}: {} points in {} levels, {} nodes, root spacing {:g}; {:.1f} MB in {:.1f} s "
        "({:.2f} M points/s)\n",
        options.output, summary.points, summary.levels.size(), summary.nodes(),
        summary.cube.rootSpacing, static_cast<double>(written.bytes) * 1e-6, seconds,
        static_cast<double>(summary.points) * 1e-6 / seconds);
    return 0;
}

}  // namespace

Command addIndexCommand(CLI::App& parent) {
    auto options = std::make_shared<IndexOptions>();
    CLI::App* index = parent.add_subcommand(
        "index", "Any scans, of any size, to one COPC file: a level-of-detail octree, out of core");
    index->add_option("scans", options->sources, "Scan files (merged into one index)")->required();
    index->add_option("-o,--output", options->output, "COPC file to write (*.copc.laz)")
        ->required();
    index->add_option("--threads", options->threads, "Threads (default: every core)")
        ->check(CLI::Range(0u, 1024u));
    index
        ->add_option("--memory", options->memoryMegabytes,
                     fmt::format("Memory budget in MB (default {})", kDefaultMemoryMegabytes))
        ->check(CLI::Range(std::size_t{64}, std::size_t{1} << 24));
    index->add_option("--tmp", options->temporaryDirectory,
                      "Folder for temporary files (default: the output's folder)");
    return {index, [options] { return runIndex(*options); }};
}

}  // namespace subscan::cli
