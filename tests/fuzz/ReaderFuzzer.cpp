// libFuzzer entry point for one reader, chosen at compile time by SUBSCAN_FUZZ_FORMAT.
// A subscan::Error is the expected answer to bad bytes; anything else (a crash, a sanitizer
// report, another exception, a hang, an allocation over the RSS limit) is a finding.
#include <cstddef>
#include <cstdint>
#include <span>

#include "core/Error.h"
#include "io/ScanLoader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::span<const std::byte> file(reinterpret_cast<const std::byte*>(data), size);
    try {
        const subscan::LoadedScan scan = subscan::decodeScan(file, subscan::SUBSCAN_FUZZ_FORMAT);
        // Touch the result so the invariants the renderer relies on are checked too.
        const subscan::PointCloud& cloud = scan.cloud;
        if (cloud.size() == 0 || (cloud.hasColors() && cloud.colors.size() != cloud.size()) ||
            (cloud.hasNormals() && cloud.normals.size() != cloud.size()) ||
            (cloud.hasIntensities() && cloud.intensities.size() != cloud.size())) {
            __builtin_trap();
        }
        for (const subscan::Triangle& triangle : cloud.triangles) {
            for (const std::uint32_t index : triangle) {
                if (index >= cloud.size()) {
                    __builtin_trap();
                }
            }
        }
    } catch (const subscan::Error&) {
    }
    return 0;
}
