#include "gpu/ShaderSources.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "core/Error.h"
#include "gpu/EmbeddedShaders.h"

namespace subscan {

namespace {

std::optional<std::filesystem::path> overrideFromEnvironment() {
    if (const char* directory = std::getenv("SUBSCAN_SHADER_DIR"); directory && *directory) {
        return std::filesystem::path(directory);
    }
    return std::nullopt;
}

/// A mistyped override would otherwise leave every shader embedded without a word.
std::optional<std::filesystem::path> checked(std::optional<std::filesystem::path> directory) {
    std::error_code error;
    if (directory && !std::filesystem::is_directory(*directory, error)) {
        throw Error(fmt::format(
            "the shader override directory '{}' (SUBSCAN_SHADER_DIR) is not a directory{}",
            directory->string(), error ? " (" + error.message() + ")" : std::string()));
    }
    return directory;
}

}  // namespace

ShaderSources::ShaderSources() : ShaderSources(overrideFromEnvironment()) {}

ShaderSources::ShaderSources(std::optional<std::filesystem::path> overrideDirectory)
    : overrideDirectory_(checked(std::move(overrideDirectory))) {}

std::string ShaderSources::raw(std::string_view path) const {
    if (overrideDirectory_) {
        const std::filesystem::path file = *overrideDirectory_ / path;
        if (std::ifstream stream{file, std::ios::binary}) {
            std::ostringstream text;
            text << stream.rdbuf();
            return text.str();
        }
    }
    for (const EmbeddedShader& shader : embeddedShaders()) {
        if (shader.path == path) {
            return std::string(shader.source);
        }
    }
    throw Error(fmt::format("the shader '{}' is not part of this build", path));
}

namespace {

/// Expands includes into `out`. `included` lists the files expanded so far (each file once,
/// which also breaks cycles); a file's position in it is its #line source-string number.
void expand(const ShaderSources& sources, std::string_view path, std::string& out,
            std::vector<std::string>& included) {
    const std::string text = sources.raw(path);
    const int sourceNumber = static_cast<int>(included.size());
    std::istringstream lines(text);
    std::string line;
    int lineNumber = 0;
    while (std::getline(lines, line)) {
        ++lineNumber;
        const std::size_t first = line.find_first_not_of(" \t");
        // Only quoted includes are ours; <...> ones sit in the C++-only part of shared headers.
        if (first != std::string::npos && line.compare(first, 8, "#include") == 0 &&
            line.find('<', first) == std::string::npos) {
            const std::size_t open = line.find('"', first);
            const std::size_t close = open == std::string::npos ? open : line.find('"', open + 1);
            if (close == std::string::npos) {
                throw Error(fmt::format("{}:{}: malformed #include", path, lineNumber));
            }
            const std::string target = line.substr(open + 1, close - open - 1);
            bool seen = false;
            for (const std::string& done : included) {
                seen = seen || done == target;
            }
            if (!seen) {
                included.push_back(target);
                out += fmt::format("#line 1 {}\n", included.size() - 1);
                expand(sources, target, out, included);
            }
            out += fmt::format("#line {} {}\n", lineNumber + 1, sourceNumber);
            continue;
        }
        out += line;
        out += '\n';
    }
}

}  // namespace

std::string ShaderSources::load(std::string_view path, std::string_view defines) const {
    std::string body;
    std::vector<std::string> included{std::string(path)};
    expand(*this, path, body, included);

    // #version must stay the first line; the defines and the first #line follow it.
    const std::size_t versionStart = body.find("#version");
    if (versionStart == std::string::npos) {
        throw Error(fmt::format("the shader '{}' has no #version line", path));
    }
    const std::size_t versionEnd = body.find('\n', versionStart);
    std::string result = body.substr(0, versionEnd + 1);
    result += defines;
    if (!defines.empty() && defines.back() != '\n') {
        result += '\n';
    }
    const int versionLine =
        1 + static_cast<int>(std::count(body.begin(), body.begin() + versionEnd, '\n'));
    result += fmt::format("#line {} 0\n", versionLine + 1);
    result += body.substr(versionEnd + 1);
    return result;
}

}  // namespace subscan
