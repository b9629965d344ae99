// Reader throughput. Real scans come from $SUBSCAN_TEST_DATA or ../shared/data; a benchmark
// whose file is absent reports an error instead of a time. Bytes per second = file bytes.
#include <cstdlib>
#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>

#include "io/MappedFile.h"
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

BENCHMARK_CAPTURE(loadFile, happy_binary_ply, std::string("happy_stand_registered.ply"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(loadFile, bunny_ascii_ply, std::string("bun_zipper.ply"))
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
