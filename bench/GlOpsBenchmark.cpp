// What the GL primitives the passes use cost on this driver, at one frame's size: buffer fills
// and texture clears (the driver's, a framebuffer's, and GpuClear's compute shader), and a small
// read-back: the measurements behind GpuClear's choice of path. Each is
// timed both by a GL timer query and by glFinish + clock; the median of the repetitions is
// printed with the bandwidth it implies. Usage: subscan_gl_ops_bench [WIDTH HEIGHT [REPEATS]].
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "core/Error.h"
#include "gpu/GlContext.h"
#include "gpu/GlObjects.h"
#include "gpu/GpuClear.h"
#include "gpu/ShaderSources.h"

namespace subscan {
namespace {

struct Timing {
    double queryMs = 0.0;
    double finishMs = 0.0;
};

double median(std::vector<double> values) {
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    return values[values.size() / 2];
}

Timing measure(const std::function<void()>& operation, int repeats) {
    TimerQuery query;
    std::vector<double> queried, finished;
    operation();  // first use allocates and compiles
    glFinish();
    for (int i = 0; i < repeats; ++i) {
        glBeginQuery(GL_TIME_ELAPSED, query.id());
        operation();
        glEndQuery(GL_TIME_ELAPSED);
        GLuint64 nanoseconds = 0;
        glGetQueryObjectui64v(query.id(), GL_QUERY_RESULT, &nanoseconds);
        queried.push_back(static_cast<double>(nanoseconds) * 1e-6);

        glFinish();
        const auto start = std::chrono::steady_clock::now();
        operation();
        glFinish();
        finished.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count());
    }
    return {median(queried), median(finished)};
}

void report(const std::string& name, std::size_t bytes, const Timing& timing) {
    const double gigabytes = static_cast<double>(bytes) * 1e-9;
    std::printf("%-40s %8.1f MB  query %8.3f ms (%7.1f GB/s)  finish %8.3f ms (%7.1f GB/s)\n",
                name.c_str(), static_cast<double>(bytes) * 1e-6, timing.queryMs,
                gigabytes / (timing.queryMs * 1e-3), timing.finishMs,
                gigabytes / (timing.finishMs * 1e-3));
}

int run(int width, int height, int repeats) {
    auto context = createHeadlessContext();
    std::printf("%s, %dx%d, median of %d\n", context->capabilities().renderer.c_str(), width,
                height, repeats);
    const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);

    Buffer buffer(pixels * 8, nullptr, "buffer");
    report("buffer fill, glClearNamedBufferData", pixels * 8,
           measure([&] { buffer.fill(0xFFFFFFFFu); }, repeats));
    GpuClear clears(ShaderSources(), context->capabilities());
    report("buffer fill, GpuClear compute", pixels * 8,
           measure([&] { clears.buffer(buffer, 0xFFFFFFFFu, ClearPath::Compute); }, repeats));

    const struct {
        TextureFormat format;
        const char* name;
        std::size_t bytes;
    } formats[] = {{TextureFormat::R8, "R8", 1},           {TextureFormat::R32F, "R32F", 4},
                   {TextureFormat::R32UI, "R32UI", 4},     {TextureFormat::RGBA8, "RGBA8", 4},
                   {TextureFormat::RG32F, "RG32F", 8},     {TextureFormat::RGBA16F, "RGBA16F", 8},
                   {TextureFormat::RGBA32F, "RGBA32F", 16}};
    GLuint framebuffer = 0;
    glCreateFramebuffers(1, &framebuffer);
    for (const auto& format : formats) {
        Texture texture(format.format, width, height, format.name);
        report(std::string("texture clear, framebuffer, ") + format.name, pixels * format.bytes,
               measure(
                   [&] {
                       glNamedFramebufferTexture(framebuffer, GL_COLOR_ATTACHMENT0, texture.id(),
                                                 0);
                       if (format.format == TextureFormat::R32UI) {
                           const GLuint value[4] = {7, 7, 7, 7};
                           glClearNamedFramebufferuiv(framebuffer, GL_COLOR, 0, value);
                       } else {
                           const GLfloat value[4] = {1, 1, 1, 1};
                           glClearNamedFramebufferfv(framebuffer, GL_COLOR, 0, value);
                       }
                   },
                   repeats));
        report(std::string("texture clear, GpuClear compute, ") + format.name,
               pixels * format.bytes,
               measure(
                   [&] {
                       if (format.format == TextureFormat::R32UI) {
                           clears.textureUint(texture, 7, ClearPath::Compute);
                       } else {
                           clears.texture(texture, glm::vec4(1.0f), ClearPath::Compute);
                       }
                   },
                   repeats));
        report(std::string("texture clear, glClearTexImage, ") + format.name, pixels * format.bytes,
               measure(
                   [&] {
                       if (format.format == TextureFormat::R32UI) {
                           texture.clearUint(7);
                       } else {
                           texture.clear(glm::vec4(1.0f));
                       }
                   },
                   repeats));
    }

    glDeleteFramebuffers(1, &framebuffer);

    std::vector<std::uint32_t> small(16);
    report("read back 64 bytes", 64,
           measure([&] { buffer.download(0, 64, small.data()); }, repeats));
    return 0;
}

}  // namespace
}  // namespace subscan

int main(int argc, char** argv) {
    try {
        const int width = argc > 2 ? std::atoi(argv[1]) : 1920;
        const int height = argc > 2 ? std::atoi(argv[2]) : 1080;
        const int repeats = argc > 3 ? std::atoi(argv[3]) : 50;
        if (argc == 2 || argc > 4 || width <= 0 || height <= 0 || repeats <= 0) {
            std::fprintf(stderr, "usage: subscan_gl_ops_bench [WIDTH HEIGHT [REPEATS]]\n");
            return 2;
        }
        return subscan::run(width, height, repeats);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "subscan_gl_ops_bench: %s\n", error.what());
        return 1;
    }
}
