// libFuzzer entry point for the EPT parsers: the input up to its first NUL byte is an ept.json,
// the rest a hierarchy page. A subscan::Error is the expected answer to bad text; anything else
// (a crash, a sanitizer report, another exception, a hang) is a finding.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/Error.h"
#include "lod/NodeSource.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view input(reinterpret_cast<const char*>(data), size);
    const std::size_t split = std::min(input.find('\0'), input.size());
    try {
        const subscan::lod::EptDescription description =
            subscan::lod::parseEptDescription(input.substr(0, split));
        // What the selection computes with must be finite and positive.
        if (!(description.cube.halfSize > 0.0) || !std::isfinite(description.cube.halfSize) ||
            !(description.cube.rootSpacing > 0.0) || !std::isfinite(description.cube.rootSpacing)) {
            __builtin_trap();
        }
    } catch (const subscan::Error&) {
    }
    try {
        const subscan::lod::EptHierarchyPage page = subscan::lod::parseEptHierarchyPage(
            split < input.size() ? input.substr(split + 1) : std::string_view{});
        for (const subscan::lod::StreamedNode& node : page.nodes) {
            if (node.pointCount == 0) {
                __builtin_trap();
            }
        }
    } catch (const subscan::Error&) {
    }
    return 0;
}
