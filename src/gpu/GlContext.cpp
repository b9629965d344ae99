#include "gpu/GlContext.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>

#include <epoxy/gl.h>
#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

namespace {

bool hasExtension(const char* name) {
    GLint count = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &count);
    for (GLint i = 0; i < count; ++i) {
        const auto* extension =
            reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, static_cast<GLuint>(i)));
        if (extension != nullptr && std::strcmp(extension, name) == 0) {
            return true;
        }
    }
    return false;
}

std::string glString(GLenum name) {
    const auto* text = reinterpret_cast<const char*>(glGetString(name));
    return text != nullptr ? text : "";
}

void GLAPIENTRY collectDebugErrors(GLenum, GLenum type, GLuint, GLenum severity, GLsizei,
                                   const GLchar* message, const void* user) {
    if (type == GL_DEBUG_TYPE_ERROR || severity == GL_DEBUG_SEVERITY_HIGH) {
        auto* errors = static_cast<std::vector<std::string>*>(const_cast<void*>(user));
        errors->emplace_back(message);
    }
}

}  // namespace

std::vector<std::string> GlContext::takeDebugErrors() {
    std::vector<std::string> errors;
    errors.swap(debugErrors_);
    for (GLenum error = glGetError(); error != GL_NO_ERROR; error = glGetError()) {
        errors.push_back(fmt::format("glGetError 0x{:04x}", error));
    }
    return errors;
}

void GlContext::throwOnErrors(std::string_view during) {
    if (const std::vector<std::string> errors = takeDebugErrors(); !errors.empty()) {
        throw Error(fmt::format("OpenGL reported an error {}: {}", during, errors.front()));
    }
}

bool glDebugOutputRequested() {
#ifndef NDEBUG
    return true;
#else
    const char* requested = std::getenv("SUBSCAN_GL_DEBUG");
    return requested != nullptr && std::string_view(requested) == "1";
#endif
}

void GlContext::initialize(bool debugOutput) {
    capabilities_.vendor = glString(GL_VENDOR);
    capabilities_.renderer = glString(GL_RENDERER);
    capabilities_.version = glString(GL_VERSION);
    const std::string& renderer = capabilities_.renderer;
    capabilities_.software = renderer.find("llvmpipe") != std::string::npos ||
                             renderer.find("softpipe") != std::string::npos ||
                             renderer.find("swrast") != std::string::npos ||
                             renderer.find("SwiftShader") != std::string::npos;
    capabilities_.int64Atomics =
        hasExtension("GL_NV_shader_atomic_int64") && hasExtension("GL_ARB_gpu_shader_int64");
    GLint64 blockBytes = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &blockBytes);
    capabilities_.maxStorageBlockBytes = static_cast<std::uint64_t>(blockBytes);
    GLint texelLimit = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &texelLimit);
    capabilities_.maxTextureBufferTexels = static_cast<std::uint64_t>(std::max(texelLimit, 0));
    glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, 0, &capabilities_.maxComputeWorkGroupsX);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &capabilities_.maxTextureSize);

    if (debugOutput) {
        glEnable(GL_DEBUG_OUTPUT);
        glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
        glDebugMessageCallback(collectDebugErrors, &debugErrors_);
    }
}

}  // namespace subscan
