// Reader throughput. Real scans come from $SUBSCAN_TEST_DATA or ../shared/data; a benchmark
// whose file is absent reports an error instead of a time. Bytes per second = file bytes.
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include <glm/vec4.hpp>

#include "core/LocalSpacing.h"
#include "core/Spacing.h"
#include "io/LasReader.h"
#include "io/MappedFile.h"
#include "io/ReadContext.h"
#include "io/ScanLoader.h"

namespace {

std::filesystem::path dataDirectory() {
    if (const char* directory = std::getenv("SUBSCAN_TEST_DATA"); directory && *directory) {
        return directory;
    }
    return std::filesystem::path(SUBSCAN_SOURCE_DIR) / ".." / "shared" / "data";
}

void loadFile(benchmark::State& state, const std::string& name) {
    const std::filesystem::path path = dataDirectory() / name;
    if (!std::filesystem::exists(path)) {
        state.SkipWithError(("missing " + path.string()).c_str());
        return;
    }
    std::size_t points = 0;
    for (auto _ : state) {
        const subscan::LoadedScan scan = subscan::loadScan(path.string());
        points = scan.cloud.size();
        benchmark::DoNotOptimize(scan.cloud.positions.data());
    }
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                            static_cast<std::int64_t>(std::filesystem::file_size(path)));
    state.counters["points"] = static_cast<double>(points);
}

/// LAZ decompression alone (the point records, before the cloud is built) on `threads` threads
/// (0: one per core); items per second = points per second, in wall-clock time.
void decodeLaz(benchmark::State& state, const std::string& name, unsigned threads) {
    const std::filesystem::path path = dataDirectory() / name;
    if (!std::filesystem::exists(path)) {
        state.SkipWithError(("missing " + path.string()).c_str());
        return;
    }
    const subscan::MappedFile file(path);
    std::size_t points = 0;
    for (auto _ : state) {
        subscan::ReadContext context;
        context.decodeThreads = threads;
        const subscan::LasRecords records = subscan::readLasRecords(file.bytes(), context);
        points = records.size();
        benchmark::DoNotOptimize(records.bytes.data());
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * points));
}

BENCHMARK_CAPTURE(decodeLaz, autzen_format3_1_thread, std::string("autzen_trim.laz"), 1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(decodeLaz, autzen_format3_all_threads, std::string("autzen_trim.laz"), 0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(decodeLaz, lone_star_format1_1_thread, std::string("lone_star.laz"), 1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(decodeLaz, lone_star_format1_all_threads, std::string("lone_star.laz"), 0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(decodeLaz, lone_star_copc_1_thread, std::string("lone_star.copc.laz"), 1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(decodeLaz, lone_star_copc_all_threads, std::string("lone_star.copc.laz"), 0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(loadFile, autzen_laz, std::string("autzen_trim.laz"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(loadFile, autzen_las, std::string("autzen_trim.las"))
    ->Unit(benchmark::kMillisecond);

// E57: the same 30,571 points as double floats and as 32-bit scaled integers.
BENCHMARK_CAPTURE(loadFile, bunny_e57_double, std::string("bunnyDouble.e57"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(loadFile, bunny_e57_int32, std::string("bunnyInt32.e57"))
    ->Unit(benchmark::kMillisecond);

BENCHMARK_CAPTURE(loadFile, happy_binary_ply, std::string("happy_stand_registered.ply"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(loadFile, bunny_ascii_ply, std::string("bun_zipper.ply"))
    ->Unit(benchmark::kMillisecond);

/// What the renderer adds to a load: h (estimateSpacing), and with `local` also the local
/// spacing (estimateLocalSpacing, on every core). `source` is a file name in the data folder
/// or synthetic:NAME.
void pointSpacing(benchmark::State& state, const std::string& source, bool local) {
    const bool synthetic = source.starts_with("synthetic:");
    const std::filesystem::path path = dataDirectory() / source;
    if (!synthetic && !std::filesystem::exists(path)) {
        state.SkipWithError(("missing " + path.string()).c_str());
        return;
    }
    const subscan::LoadedScan scan = subscan::loadScan(synthetic ? source : path.string());
    for (auto _ : state) {
        const double h = subscan::estimateSpacing(scan.cloud);
        benchmark::DoNotOptimize(h);
        if (local) {
            const std::vector<glm::vec4> spacing = subscan::estimateLocalSpacing(scan.cloud, h);
            benchmark::DoNotOptimize(spacing.data());
        }
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * scan.cloud.size()));
    state.counters["points"] = static_cast<double>(scan.cloud.size());
}

BENCHMARK_CAPTURE(pointSpacing, autzen_h, std::string("autzen_trim.las"), false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(pointSpacing, autzen_h_and_local, std::string("autzen_trim.las"), true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(pointSpacing, station_h, std::string("synthetic:outdoor-station"), false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(pointSpacing, station_h_and_local, std::string("synthetic:outdoor-station"), true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(pointSpacing, happy_h, std::string("happy_stand_registered.ply"), false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(pointSpacing, happy_h_and_local, std::string("happy_stand_registered.ply"), true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
