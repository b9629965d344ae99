// Frame and per-pass times of the render modes at 1920x1080 (llvmpipe or a GPU, whichever EGL
// gives). Clouds: the Happy Buddha scans (1.1 M points, from $SUBSCAN_TEST_DATA or
// ../shared/data) and a 3.4 M-point virtual scan of the sculpture. Each iteration's time is the
// sum of the pass timers (glFinish + clock on software renderers, GL timer queries on GPUs); the
// counters give each pass's mean in milliseconds.
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include <benchmark/benchmark.h>

#include "core/Camera.h"
#include "gpu/GlContext.h"
#include "io/ScanLoader.h"
#include "render/Renderer.h"

namespace subscan {
namespace {

std::filesystem::path dataDirectory() {
    if (const char* directory = std::getenv("SUBSCAN_TEST_DATA"); directory && *directory) {
        return directory;
    }
    return std::filesystem::path(SUBSCAN_SOURCE_DIR) / ".." / "shared" / "data";
}

/// One uploaded cloud per source for the whole run.
struct Fixture {
    LoadedScan scan;
    std::unique_ptr<Renderer> renderer;
};

Fixture& fixture(const std::string& source) {
    // The context is declared first so that it is destroyed last, after the renderers' GL objects.
    static std::unique_ptr<GlContext> context = createHeadlessContext();
    static std::map<std::string, Fixture> fixtures;
    auto found = fixtures.find(source);
    if (found == fixtures.end()) {
        Fixture created;
        created.scan = loadScan(source);
        created.renderer = std::make_unique<Renderer>(*context, created.scan.cloud);
        found = fixtures.emplace(source, std::move(created)).first;
    }
    return found->second;
}

void renderFrames(benchmark::State& state, const std::string& source, RenderMode mode) {
    if (!source.starts_with("synthetic:") && !std::filesystem::exists(source)) {
        state.SkipWithError(("missing " + source).c_str());
        return;
    }
    Fixture& f = fixture(source);
    OrbitView orbit;
    orbit.yawDegrees = 0.0;
    orbit.pitchDegrees = 10.0;
    const Camera camera = orbitCamera(f.scan.cloud.bounds, orbit, 1920, 1080, 45.0);
    RenderSettings settings;
    settings.raster.mode = mode;
    f.renderer->render(camera, settings);  // warm-up: shader compilation, allocation
    std::map<std::string, double> passTotals;
    for (auto _ : state) {
        const FrameResult result = f.renderer->render(camera, settings);
        for (const PassTiming& pass : result.passes) {
            passTotals[pass.pass] += pass.milliseconds;
        }
        state.SetIterationTime(result.totalMilliseconds() / 1000.0);
    }
    for (const auto& [pass, total] : passTotals) {
        state.counters[pass + "_ms"] = total / static_cast<double>(state.iterations());
    }
    state.counters["points"] = static_cast<double>(f.scan.cloud.size());
    state.SetLabel(f.renderer->capabilities().renderer);
}

const std::string kHappy = (dataDirectory() / "happy_stand_registered.ply").string();
const std::string kLarge = "synthetic:sculpture?points=3400000";

#define SUBSCAN_RENDER_BENCHMARK(name, source, mode)    \
    BENCHMARK_CAPTURE(renderFrames, name, source, mode) \
        ->UseManualTime()                               \
        ->Unit(benchmark::kMillisecond)                 \
        ->MinTime(2.0)

SUBSCAN_RENDER_BENCHMARK(happy_points_compute, kHappy, RenderMode::Points);
SUBSCAN_RENDER_BENCHMARK(happy_points_gl, kHappy, RenderMode::PointsGl);
SUBSCAN_RENDER_BENCHMARK(happy_surface, kHappy, RenderMode::Surface);
SUBSCAN_RENDER_BENCHMARK(happy_sss, kHappy, RenderMode::Sss);
SUBSCAN_RENDER_BENCHMARK(sculpture3M4_points_compute, kLarge, RenderMode::Points);
SUBSCAN_RENDER_BENCHMARK(sculpture3M4_points_gl, kLarge, RenderMode::PointsGl);
SUBSCAN_RENDER_BENCHMARK(sculpture3M4_surface, kLarge, RenderMode::Surface);
SUBSCAN_RENDER_BENCHMARK(sculpture3M4_sss, kLarge, RenderMode::Sss);

}  // namespace
}  // namespace subscan

BENCHMARK_MAIN();
