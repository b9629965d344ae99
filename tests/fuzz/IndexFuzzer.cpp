// libFuzzer target for subscan index's writer: any bytes become LAS 1.4 point records (the
// first byte picks format 6, 7 or 8, the second the extra bytes, the third how many points a
// node may hold, 16 to 271), which are indexed into a COPC file and read back through the COPC
// reader. Every record must come back once and unchanged; anything else aborts, as a crash does.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

#include "core/Error.h"
#include "io/LasReader.h"
#include "io/MappedFile.h"
#include "lod/CopcWriter.h"
#include "lod/OctreeIndexer.h"
#include "support/MemoryRecordSource.h"
#include "support/PointRecordTestSupport.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace subscan;
    if (size < 3) {
        return 0;
    }
    const PointRecordFormat format{6 + data[0] % 3, static_cast<std::size_t>(data[1] % 8), {}};
    // Nodes of 16 to 271 points: several levels from a few hundred points, without so many tiny
    // LAZ chunks (each resets every model) that an execution takes a second.
    const std::size_t maxNodePoints = 16 + data[2];
    const std::size_t length = format.recordLength();
    const std::size_t count = (size - 3) / length;
    if (count == 0) {
        return 0;
    }
    std::vector<std::byte> records(count * length);
    std::memcpy(records.data(), data + 3, records.size());
    test::MemoryRecordSource source(records, format, {glm::dvec3(0.01), glm::dvec3(0.0)});

    // In memory where the machine has a tmpfs: the writer's fsync costs nothing there.
    const std::filesystem::path base = std::filesystem::is_directory("/dev/shm")
                                           ? std::filesystem::path("/dev/shm")
                                           : std::filesystem::temp_directory_path();
    const std::filesystem::path folder =
        base / ("subscan-fuzz-index-" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder);
    const std::filesystem::path output = folder / "out.copc.laz";
    lod::IndexSettings settings;
    settings.temporaryDirectory = folder;
    settings.maxNodePoints = maxNodePoints;
    settings.threads = 1;
    lod::writeCopc(source, output, settings);
    const MappedFile file(output);
    ReadContext context;
    const LasRecords back = readLasRecords(file.bytes(), context);
    if (test::sortedRecords(back.bytes, length) != test::sortedRecords(records, length)) {
        std::fprintf(stderr, "index fuzzer: the COPC file does not give back the records\n");
        std::abort();
    }
    std::filesystem::remove_all(folder);
    return 0;
}
