// copc.js (npm `copc`, by COPC's author: an implementation independent of ours, decoding the
// chunks with laz-perf) reads the COPC files our indexer and CopcWriter write as we meant them:
// the info VLR's cube and spacing, the header, the WKT and the extra bytes' descriptors; the same
// hierarchy (every node, by key, with its point count and chunk, reachable from the root); and
// every node's points, dimension by dimension, the records the indexer handed the writer for
// that node, which together are the input. Point formats 6, 7 and 8, extra bytes of every
// described type (and undescribed ones, which copc.js skips), in memory and out of core. The
// package comes from tests/npm's lock file, installed into the build folder by the npm_packages
// test; without node, npm or the registry these tests are skipped and say why.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <ostream>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/LasFormat.h"
#include "io/MappedFile.h"
#include "io/laz/Copc.h"
#include "lod/CopcWriter.h"
#include "lod/OctreeIndexer.h"
#include "npm/NpmPackages.h"
#include "support/Las14Records.h"
#include "support/MemoryRecordSource.h"
#include "support/TestSupport.h"

namespace subscan::lod {
namespace {

using nlohmann::json;

// ---------------------------------------------------------------------------------------------
// The records' fields, as LAS 1.4 R15 (tables 7-9 and 24) lays them out and as copc.js names
// them. A point becomes one integer per field, so that points compare and sort exactly: integers
// as themselves, doubles (and floats, widened) as their bits, every NaN as one value.

enum class FieldType { U8, I8, U16, I16, U32, I32, U64, I64, F32, F64 };

/// How copc.js hands out a field: as stored, as a scaled coordinate, or as a scan angle in
/// degrees.
enum class Meaning { Stored, PositionX, PositionY, PositionZ, ScanAngle };

struct Field {
    std::string name;  // copc.js's dimension name
    std::size_t offset = 0;
    FieldType type = FieldType::U8;
    int shift = 0;  // a bit field: (value >> shift) & (2^bits - 1)
    int bits = 0;   // 0: the whole value
    Meaning meaning = Meaning::Stored;
};

/// One extra-bytes field: its descriptor type (LAS 1.4 table 24; 0: undocumented bytes, whose
/// size the descriptor's options give) and name.
struct ExtraField {
    std::uint8_t type = 0;
    std::string name;
    std::size_t undocumentedSize = 0;  // type 0 only
};

std::size_t extraFieldSize(const ExtraField& field) {
    constexpr std::size_t kSizes[] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
    return field.type == 0 ? field.undocumentedSize : kSizes[field.type];
}

FieldType extraFieldType(std::uint8_t type) {
    constexpr FieldType kTypes[] = {FieldType::U8,  FieldType::U8,  FieldType::I8,  FieldType::U16,
                                    FieldType::I16, FieldType::U32, FieldType::I32, FieldType::U64,
                                    FieldType::I64, FieldType::F32, FieldType::F64};
    return kTypes[type];
}

/// The extra bytes VLR's payload: one 192-byte descriptor per field (LAS 1.4 table 24): data
/// type at 2, options at 3, name at 4 (32 characters), description at 160 (32). No options are
/// set (no no-data, min, max, scale or offset): copc.js 0.0.8 reads a descriptor's scale and
/// offset as big-endian doubles, so a scaled field would test its bug, not our file.
std::vector<std::byte> extraBytesDescriptors(const std::vector<ExtraField>& fields) {
    std::vector<std::byte> payload(fields.size() * 192, std::byte{0});
    for (std::size_t i = 0; i < fields.size(); ++i) {
        std::byte* descriptor = payload.data() + i * 192;
        descriptor[2] = static_cast<std::byte>(fields[i].type);
        if (fields[i].type == 0) {
            descriptor[3] = static_cast<std::byte>(fields[i].undocumentedSize);
        }
        std::memcpy(descriptor + 4, fields[i].name.data(),
                    std::min<std::size_t>(32, fields[i].name.size()));
        const std::string description = "a test field";
        std::memcpy(descriptor + 160, description.data(), description.size());
    }
    return payload;
}

/// Every field copc.js decodes from a record of `pointFormat` followed by `extras`: the standard
/// ones of formats 6-8 and each described extra field. copc.js has no dimension for undescribed
/// bytes, so they are not compared here (LazPerfReadsOurLazTest compares whole records).
std::vector<Field> fieldsOf(int pointFormat, const std::vector<ExtraField>& extras) {
    std::vector<Field> fields{
        {"X", 0, FieldType::I32, 0, 0, Meaning::PositionX},
        {"Y", 4, FieldType::I32, 0, 0, Meaning::PositionY},
        {"Z", 8, FieldType::I32, 0, 0, Meaning::PositionZ},
        {"Intensity", 12, FieldType::U16},
        {"ReturnNumber", 14, FieldType::U8, 0, 4},
        {"NumberOfReturns", 14, FieldType::U8, 4, 4},
        {"Synthetic", 15, FieldType::U8, 0, 1},
        {"KeyPoint", 15, FieldType::U8, 1, 1},
        {"Withheld", 15, FieldType::U8, 2, 1},
        {"Overlap", 15, FieldType::U8, 3, 1},
        {"ScannerChannel", 15, FieldType::U8, 4, 2},
        {"ScanDirectionFlag", 15, FieldType::U8, 6, 1},
        {"EdgeOfFlightLine", 15, FieldType::U8, 7, 1},
        {"Classification", 16, FieldType::U8},
        {"UserData", 17, FieldType::U8},
        {"ScanAngle", 18, FieldType::I16, 0, 0, Meaning::ScanAngle},
        {"PointSourceId", 20, FieldType::U16},
        {"GpsTime", 22, FieldType::F64},
    };
    std::size_t offset = 30;
    if (pointFormat >= 7) {
        fields.push_back({"Red", 30, FieldType::U16});
        fields.push_back({"Green", 32, FieldType::U16});
        fields.push_back({"Blue", 34, FieldType::U16});
        offset = 36;
    }
    if (pointFormat == 8) {
        fields.push_back({"Infrared", 36, FieldType::U16});
        offset = 38;
    }
    for (const ExtraField& extra : extras) {
        if (extra.type != 0) {
            fields.push_back({extra.name, offset, extraFieldType(extra.type)});
        }
        offset += extraFieldSize(extra);
    }
    return fields;
}

/// A double as an integer that compares exactly: its bits, one value for every NaN (a reader
/// may not keep a NaN's payload).
std::int64_t doubleKey(double value) {
    return std::isnan(value) ? std::numeric_limits<std::int64_t>::min()
                             : std::bit_cast<std::int64_t>(value);
}

template <class T>
T load(const std::byte* p) {
    T value;
    std::memcpy(&value, p, sizeof value);  // LAS is little-endian, as the hosts we test on
    return value;
}

std::int64_t fieldOfRecord(const Field& field, const std::byte* record) {
    const std::byte* p = record + field.offset;
    std::int64_t value = 0;
    switch (field.type) {
        case FieldType::U8:
            value = load<std::uint8_t>(p);
            break;
        case FieldType::I8:
            value = load<std::int8_t>(p);
            break;
        case FieldType::U16:
            value = load<std::uint16_t>(p);
            break;
        case FieldType::I16:
            value = load<std::int16_t>(p);
            break;
        case FieldType::U32:
            value = load<std::uint32_t>(p);
            break;
        case FieldType::I32:
            value = load<std::int32_t>(p);
            break;
        case FieldType::U64:
            value = static_cast<std::int64_t>(load<std::uint64_t>(p));
            break;
        case FieldType::I64:
            value = load<std::int64_t>(p);
            break;
        case FieldType::F32:
            return doubleKey(load<float>(p));
        case FieldType::F64:
            return doubleKey(load<double>(p));
    }
    return field.bits == 0 ? value : (value >> field.shift) & ((std::int64_t{1} << field.bits) - 1);
}

/// A double as read-copc.js writes it: a number, or "NaN", "Infinity", "-Infinity", "-0".
double exactDouble(const json& value) {
    if (value.is_number()) {
        return value.get<double>();
    }
    const std::string text = value.is_string() ? value.get<std::string>() : value.dump();
    if (text == "NaN")
        return std::numeric_limits<double>::quiet_NaN();
    if (text == "Infinity")
        return std::numeric_limits<double>::infinity();
    if (text == "-Infinity")
        return -std::numeric_limits<double>::infinity();
    if (text == "-0")
        return -0.0;
    ADD_FAILURE() << "not a number in copc.js's output: " << text;
    return 0.0;
}

/// Expects copc.js's double to be exactly ours (equal values: -0 and 0 are equal), and says
/// both in full when not.
void expectSameDouble(const json& theirs, double ours, std::string_view what) {
    const double value = exactDouble(theirs);
    EXPECT_EQ(value, ours) << what << ": copc.js reads " << fmt::format("{}", value)
                           << ", we wrote " << fmt::format("{}", ours);
}

/// What copc.js's value of `field` says the record held, as fieldOfRecord gives it.
std::int64_t fieldOfCopcJs(const Field& field, const json& value, const Quantization& q) {
    switch (field.meaning) {
        case Meaning::PositionX:
        case Meaning::PositionY:
        case Meaning::PositionZ: {
            // copc.js gives stored * scale + offset as a double; the stored integers are what
            // the file holds, so they are compared, exactly: the integer nearest
            // (x - offset) / scale (one step is 0.001 here, far beyond a double's rounding).
            const int axis = static_cast<int>(field.meaning) - static_cast<int>(Meaning::PositionX);
            return std::llround((exactDouble(value) - q.offset[axis]) / q.scale[axis]);
        }
        case Meaning::ScanAngle:
            // LAS 1.4 stores the angle in steps of 0.006 degrees; copc.js gives degrees (the
            // step times the stored int16), so the nearest step is the stored value exactly.
            return std::llround(exactDouble(value) / 0.006);
        case Meaning::Stored:
            break;
    }
    if (field.type == FieldType::F32 || field.type == FieldType::F64) {
        return doubleKey(exactDouble(value));  // a float32 widened to a double, both sides
    }
    if (!value.is_number_integer()) {
        ADD_FAILURE() << "copc.js gives " << field.name << " as " << value.dump()
                      << ", not an integer";
        return std::numeric_limits<std::int64_t>::max();
    }
    return value.get<std::int64_t>();
}

using Point = std::vector<std::int64_t>;  // one value per Field, in fieldsOf's order

std::vector<Point> pointsOfRecords(std::span<const std::byte> records, std::size_t length,
                                   const std::vector<Field>& fields) {
    std::vector<Point> points;
    for (std::size_t at = 0; at + length <= records.size(); at += length) {
        Point point;
        for (const Field& field : fields) {
            point.push_back(fieldOfRecord(field, records.data() + at));
        }
        points.push_back(std::move(point));
    }
    std::sort(points.begin(), points.end());
    return points;
}

std::string describe(const Point& point, const std::vector<Field>& fields) {
    std::string text;  // starts with a space
    for (std::size_t i = 0; i < fields.size(); ++i) {
        const bool real = fields[i].type == FieldType::F32 || fields[i].type == FieldType::F64;
        text += real ? fmt::format(" {}={}", fields[i].name, std::bit_cast<double>(point[i]))
                     : fmt::format(" {}={}", fields[i].name, point[i]);
    }
    return text;
}

/// Expects two sorted multisets of points to be equal; otherwise says how many differ and shows
/// a few of each side.
void expectSamePoints(const std::vector<Point>& theirs, const std::vector<Point>& ours,
                      const std::vector<Field>& fields, const std::string& where) {
    if (theirs == ours) {
        return;
    }
    std::vector<Point> onlyTheirs, onlyOurs;
    std::set_difference(theirs.begin(), theirs.end(), ours.begin(), ours.end(),
                        std::back_inserter(onlyTheirs));
    std::set_difference(ours.begin(), ours.end(), theirs.begin(), theirs.end(),
                        std::back_inserter(onlyOurs));
    std::string shown;
    for (std::size_t i = 0; i < std::min<std::size_t>(2, onlyTheirs.size()); ++i) {
        shown += "\n  copc.js only:" + describe(onlyTheirs[i], fields);
    }
    for (std::size_t i = 0; i < std::min<std::size_t>(2, onlyOurs.size()); ++i) {
        shown += "\n  written only:" + describe(onlyOurs[i], fields);
    }
    ADD_FAILURE() << where << ": copc.js decodes " << theirs.size() << " points, "
                  << onlyTheirs.size() << " of them not among the " << ours.size() << " written; "
                  << onlyOurs.size() << " written points missing" << shown;
}

// ---------------------------------------------------------------------------------------------

std::string keyText(const laz::VoxelKey& key) {
    return fmt::format("{}-{}-{}-{}", key.level, key.x, key.y, key.z);
}

laz::VoxelKey parseKey(const std::string& text) {
    laz::VoxelKey key;
    if (std::sscanf(text.c_str(), "%d-%d-%d-%d", &key.level, &key.x, &key.y, &key.z) != 4) {
        ADD_FAILURE() << "copc.js gives a node key that is not level-x-y-z: " << text;
    }
    return key;
}

/// Hands every node on to the COPC writer and keeps its records: what the writer was given.
class RecordingSink final : public NodeSink {
  public:
    explicit RecordingSink(NodeSink& next) : next_(next) {}
    void writeNode(const laz::VoxelKey& key, std::span<const std::byte> records,
                   std::size_t pointCount) override {
        next_.writeNode(key, records, pointCount);
        if (pointCount == 0) {
            return;  // the writer leaves empty nodes out of the hierarchy
        }
        std::lock_guard lock(mutex_);
        const bool added =
            nodes_.emplace(keyText(key), std::vector<std::byte>(records.begin(), records.end()))
                .second;
        duplicates_ += added ? 0 : 1;
    }
    const std::map<std::string, std::vector<std::byte>>& nodes() const { return nodes_; }
    std::size_t duplicates() const { return duplicates_; }

  private:
    NodeSink& next_;
    std::mutex mutex_;
    std::map<std::string, std::vector<std::byte>> nodes_;
    std::size_t duplicates_ = 0;
};

struct CopcJsCase {
    std::string name;
    int pointFormat = 6;
    std::vector<ExtraField> extras;
    std::size_t points = 6'000;
    /// The indexer's memory budget: 1 MB cuts these clouds into chunks of its least size (eight
    /// nodes' worth), so the out-of-core path (temporary files, levels built above the chunks)
    /// runs; 1 GB keeps them in one piece.
    std::size_t memoryBytes = std::size_t{1} << 30;
};

/// Records of the case's format on a 40 x 40 m waving terrain (millimetre steps), their other
/// fields the LAZ tests' random ones (every field changing, runs, values at their limits).
std::vector<std::byte> caseRecords(const CopcJsCase& c, const PointRecordFormat& format) {
    test::Las14RecordOptions options;
    options.pointFormat = c.pointFormat;
    options.extraBytes = format.extraBytes;
    options.seed = static_cast<std::uint32_t>(77 + c.pointFormat + c.points);
    std::vector<std::byte> records = test::randomLas14Records(options, c.points);
    std::mt19937 random(options.seed);
    std::uniform_real_distribution<double> along(0.0, 40.0);
    const std::size_t length = format.recordLength();
    const std::vector<Field> fields = fieldsOf(c.pointFormat, c.extras);
    for (std::size_t i = 0; i < c.points; ++i) {
        std::byte* record = records.data() + i * length;
        const double x = along(random), y = along(random);
        const std::int32_t stored[3] = {
            static_cast<std::int32_t>(std::lround(x * 1000)),
            static_cast<std::int32_t>(std::lround(y * 1000)),
            static_cast<std::int32_t>(std::lround(2000 * std::sin(x / 5) * std::cos(y / 7)))};
        std::memcpy(record, stored, sizeof stored);
        // copc.js turns 64-bit integers into JavaScript numbers and refuses those beyond 2^53:
        // keep these fields' values within, their sign and low bits still random.
        for (const Field& field : fields) {
            if (field.type == FieldType::U64) {
                const auto value = load<std::uint64_t>(record + field.offset) >> 11;
                std::memcpy(record + field.offset, &value, sizeof value);
            } else if (field.type == FieldType::I64) {
                const auto value = load<std::int64_t>(record + field.offset) >> 11;
                std::memcpy(record + field.offset, &value, sizeof value);
            }
        }
    }
    return records;
}

constexpr std::string_view kWkt =
    "PROJCS[\"WGS 84 / UTM zone 33N\",GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS "
    "84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]],"
    "PROJECTION[\"Transverse_Mercator\"],PARAMETER[\"central_meridian\",15],UNIT[\"metre\",1],"
    "AUTHORITY[\"EPSG\",\"32633\"]]";

const Quantization kMillimetres{glm::dvec3(0.001), glm::dvec3(500000.0, 4000000.0, 100.0)};

/// How GoogleTest names a case in its messages.
void PrintTo(const CopcJsCase& c, std::ostream* out) {
    *out << c.name;
}

/// The cloud indexed into a COPC file, and what the indexer handed the writer.
struct Written {
    std::filesystem::path copc;
    IndexSummary summary;
    std::map<std::string, std::vector<std::byte>> nodes;  // by key, the nodes holding points
};

Written indexToCopc(const test::TempDir& folder, test::MemoryRecordSource& source,
                    std::size_t memoryBytes) {
    Written written;
    written.copc = folder / "ours.copc.laz";
    IndexSettings settings;
    settings.temporaryDirectory = folder.path();
    settings.maxNodePoints = 500;  // several levels and dozens of nodes from thousands of points
    settings.memoryBytes = memoryBytes;
    settings.threads = 2;
    CopcWriter writer(written.copc, source.info(),
                      octreeCubeFor(source.info().min, source.info().max));
    RecordingSink sink(writer);
    written.summary = buildOctree(source, sink, settings);
    writer.finish();
    EXPECT_EQ(sink.duplicates(), 0u) << "the indexer handed a node over twice";
    written.nodes = sink.nodes();
    return written;
}

/// The header, the WKT and the extra bytes' descriptors as copc.js reads them.
void expectTheHeader(const json& theirs, const CopcJsCase& c, const PointRecordFormat& format,
                     const test::MemoryRecordSource& source, std::span<const std::byte> input) {
    const json& header = theirs.at("header");
    const std::size_t length = format.recordLength();
    EXPECT_EQ(header.at("majorVersion"), 1);
    EXPECT_EQ(header.at("minorVersion"), 4);
    EXPECT_EQ(header.at("pointDataRecordFormat"), c.pointFormat);
    EXPECT_EQ(header.at("pointDataRecordLength"), length);
    EXPECT_EQ(header.at("pointCount"), c.points);
    std::vector<std::uint64_t> byReturn(15, 0);
    for (std::size_t i = 0; i < c.points; ++i) {
        const int returnNumber = static_cast<int>(input[i * length + 14]) & 0x0F;
        if (returnNumber >= 1) {
            ++byReturn[returnNumber - 1];
        }
    }
    EXPECT_EQ(header.at("pointCountByReturn").get<std::vector<std::uint64_t>>(), byReturn);
    for (int axis = 0; axis < 3; ++axis) {
        const std::string axisName(1, "XYZ"[axis]);
        expectSameDouble(header.at("scale")[axis], kMillimetres.scale[axis], axisName + " scale");
        expectSameDouble(header.at("offset")[axis], kMillimetres.offset[axis],
                         axisName + " offset");
        expectSameDouble(header.at("min")[axis], source.info().min[axis], "least " + axisName);
        expectSameDouble(header.at("max")[axis], source.info().max[axis], "greatest " + axisName);
    }
    EXPECT_EQ(theirs.at("wkt"), kWkt);

    // Every extra field by name, type and size.
    ASSERT_EQ(theirs.at("extraBytes").size(), c.extras.size());
    for (std::size_t i = 0; i < c.extras.size(); ++i) {
        const json& eb = theirs.at("extraBytes")[i];
        EXPECT_EQ(eb.at("name"), c.extras[i].name);
        EXPECT_EQ(eb.at("length"), extraFieldSize(c.extras[i]));
        const FieldType type = extraFieldType(c.extras[i].type);
        const char* kind = c.extras[i].type == 0                              ? nullptr
                           : type == FieldType::F32 || type == FieldType::F64 ? "float"
                           : type == FieldType::I8 || type == FieldType::I16 ||
                                   type == FieldType::I32 || type == FieldType::I64
                               ? "signed"
                               : "unsigned";
        EXPECT_EQ(eb.at("type"), kind == nullptr ? json() : json(kind)) << eb.at("name");
    }
}

/// The info VLR: the indexer's cube (copc.js gives it as min and max corners, centre -/+ the
/// half size, which it computes as we do here: exactly the same doubles), its spacing, and the
/// GPS time range of the points (NaN times ignored, as the writer does).
void expectTheInfo(const json& theirs, const OctreeCube& cube, std::span<const std::byte> input,
                   std::size_t length) {
    const json& info = theirs.at("info");
    ASSERT_EQ(info.at("cube").size(), 6u);
    for (int axis = 0; axis < 3; ++axis) {
        expectSameDouble(info.at("cube")[axis], cube.center[axis] - cube.halfSize,
                         fmt::format("the cube's least {}", "XYZ"[axis]));
        expectSameDouble(info.at("cube")[3 + axis], cube.center[axis] + cube.halfSize,
                         fmt::format("the cube's greatest {}", "XYZ"[axis]));
    }
    expectSameDouble(info.at("spacing"), cube.rootSpacing, "the root spacing");
    double gpsMin = std::numeric_limits<double>::infinity(), gpsMax = -gpsMin;
    for (std::size_t at = 0; at < input.size(); at += length) {
        const double time = load<double>(input.data() + at + 22);
        if (!std::isnan(time)) {
            gpsMin = std::min(gpsMin, time);
            gpsMax = std::max(gpsMax, time);
        }
    }
    expectSameDouble(info.at("gpsTimeRange")[0], gpsMin, "the least GPS time");
    expectSameDouble(info.at("gpsTimeRange")[1], gpsMax, "the greatest GPS time");
}

/// The hierarchy: the nodes that hold points are the nodes the writer was given, with their
/// point counts, and where our own reader finds their chunks; every node is reachable from the
/// root (its parent is a node too), as a reader walking down the tree needs.
void expectTheHierarchy(const json& theirs, const Written& written, std::size_t length) {
    const MappedFile file(written.copc);
    const laz::CopcInfo ourInfo = laz::parseCopcInfo(
        file.bytes().subspan(las::kHeaderSize14 + las::kVlrHeaderSize, 160));  // first VLR
    std::map<std::string, laz::Chunk> ourChunks;
    for (const laz::CopcNode& node : laz::readCopcHierarchy(file.bytes(), ourInfo)) {
        ourChunks[keyText(node.key)] = node.chunk;
    }
    EXPECT_GE(theirs.at("pages"), 1);
    std::set<std::string> allKeys;
    std::map<std::string, std::uint64_t> theirCounts, writtenCounts;
    for (const json& node : theirs.at("nodes")) {
        allKeys.insert(node.at("key").get<std::string>());
        if (node.at("pointCount") != 0) {
            theirCounts[node.at("key").get<std::string>()] =
                node.at("pointCount").get<std::uint64_t>();
        }
    }
    for (const auto& [key, records] : written.nodes) {
        writtenCounts[key] = records.size() / length;
    }
    EXPECT_EQ(theirCounts, writtenCounts);
    for (const json& node : theirs.at("nodes")) {
        const std::string key = node.at("key");
        const laz::VoxelKey k = parseKey(key);
        if (k.level > 0) {
            EXPECT_TRUE(allKeys.contains(keyText({k.level - 1, k.x >> 1, k.y >> 1, k.z >> 1})))
                << "node " << key << " has no parent in the hierarchy";
        } else {
            EXPECT_EQ(key, "0-0-0-0");
        }
        const auto ours = ourChunks.find(key);
        if (node.at("pointCount") != 0 && ours != ourChunks.end()) {
            EXPECT_EQ(node.at("pointDataOffset"), ours->second.offset) << key;
            EXPECT_EQ(node.at("pointDataLength"), ours->second.byteSize) << key;
            EXPECT_EQ(node.at("pointCount"), ours->second.pointCount) << key;
        }
    }
    EXPECT_EQ(ourChunks.size(), theirCounts.size());
}

/// Expects every point of copc.js's node `key` to lie inside the node's voxel, from copc.js's
/// cube and coordinates. A point on a face between two voxels belongs to either (the indexer
/// puts it in the upper one): the bounds are closed, widened by 1e-12 of the cube for the
/// rounding of both sides' arithmetic (a millimetre step is 1e-5 of these cubes).
void expectInsideTheVoxel(const std::string& key, const json& dimensions, const json& cube) {
    const laz::VoxelKey k = parseKey(key);
    const double cells = static_cast<double>(std::int64_t{1} << k.level);
    const int cell[3] = {k.x, k.y, k.z};
    std::size_t outside = 0;
    for (int axis = 0; axis < 3; ++axis) {
        const double least = cube[axis].get<double>();
        const double cubeSide = cube[3 + axis].get<double>() - least;
        const double side = cubeSide / cells;
        const double low = least + side * cell[axis] - 1e-12 * cubeSide;
        const double high = least + side * (cell[axis] + 1) + 1e-12 * cubeSide;
        const std::string name(1, "XYZ"[axis]);
        const json& values = dimensions.at(name);
        for (std::size_t i = 0; i < values.size(); ++i) {
            const double v = exactDouble(values[i]);
            if (!(v >= low && v <= high) && outside++ < 3) {
                ADD_FAILURE() << "node " << key << ": point " << i << "'s " << name
                              << fmt::format(" {} lies outside {}..{}", v, low, high);
            }
        }
    }
    EXPECT_EQ(outside, 0u) << key;
}

/// The points: per node, copc.js's decoded dimensions are the records the writer was given for
/// that node (as multisets: a node's order is the writer's business), inside the node's voxel;
/// together they are the input.
void expectThePoints(const json& theirs, const Written& written, const CopcJsCase& c,
                     std::span<const std::byte> input, std::size_t length) {
    const std::vector<Field> fields = fieldsOf(c.pointFormat, c.extras);
    std::set<std::string> expectedDimensions;
    for (const Field& field : fields) {
        expectedDimensions.insert(field.name);
    }
    std::vector<Point> everyPoint;
    for (const json& node : theirs.at("nodes")) {
        const std::string key = node.at("key");
        const std::size_t count = node.at("pointCount");
        if (count == 0) {
            continue;
        }
        const json& dimensions = node.at("dimensions");
        std::set<std::string> names;
        for (const auto& [name, values] : dimensions.items()) {
            names.insert(name);
            ASSERT_EQ(values.size(), count) << key << " " << name;
        }
        ASSERT_EQ(names, expectedDimensions) << key;
        expectInsideTheVoxel(key, dimensions, theirs.at("info").at("cube"));

        std::vector<Point> points(count);
        for (const Field& field : fields) {
            const json& values = dimensions.at(field.name);
            for (std::size_t i = 0; i < count; ++i) {
                points[i].push_back(fieldOfCopcJs(field, values[i], kMillimetres));
            }
        }
        std::sort(points.begin(), points.end());
        const auto given = written.nodes.find(key);
        if (given != written.nodes.end()) {
            expectSamePoints(points, pointsOfRecords(given->second, length, fields), fields,
                             "node " + key);
        }
        everyPoint.insert(everyPoint.end(), points.begin(), points.end());
    }
    std::sort(everyPoint.begin(), everyPoint.end());
    expectSamePoints(everyPoint, pointsOfRecords(input, length, fields), fields, "the file");
}

class CopcJsReadsOurCopcTest : public testing::TestWithParam<CopcJsCase> {};

TEST_P(CopcJsReadsOurCopcTest, TheSameHierarchyAndPoints) {
    const test::NpmPackages packages = test::npmPackages();
    if (!packages.unavailable.empty()) {
        GTEST_SKIP() << "copc.js is not available: " << packages.unavailable;
    }
    const CopcJsCase& c = GetParam();
    PointRecordFormat format{c.pointFormat, 0, extraBytesDescriptors(c.extras)};
    for (const ExtraField& extra : c.extras) {
        format.extraBytes += extraFieldSize(extra);
    }
    const std::vector<std::byte> input = caseRecords(c, format);
    test::MemoryRecordSource source(input, format, kMillimetres);
    source.mutableInfo().wkt = kWkt;
    const test::TempDir folder;
    const Written written = indexToCopc(folder, source, c.memoryBytes);
    if (c.memoryBytes < (std::size_t{1} << 30)) {
        ASSERT_GT(written.summary.chunks, 1u) << "the out-of-core path did not run";
    }
    ASSERT_GE(written.summary.levels.size(), 3u);
    ASSERT_GE(written.nodes.size(), 20u);

    const test::CommandResult result =
        test::runProgram(packages.node, {(packages.directory / "read-copc.js").string(),
                                         written.copc.string(), (folder / "theirs.json").string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const json theirs = json::parse(test::fileBytes(folder / "theirs.json"));
    expectTheHeader(theirs, c, format, source, input);
    expectTheInfo(theirs, written.summary.cube, input, format.recordLength());
    expectTheHierarchy(theirs, written, format.recordLength());
    expectThePoints(theirs, written, c, input, format.recordLength());
}

INSTANTIATE_TEST_SUITE_P(
    Clouds, CopcJsReadsOurCopcTest,
    testing::Values(CopcJsCase{"Format6", 6, {}},
                    // Every described type but the 64-bit ones, and undescribed bytes between them
                    // (copc.js must step over them to find the next field).
                    CopcJsCase{"Format7WithExtraBytes",
                               7,
                               {{3, "Amplitude"},
                                {2, "Deviation"},
                                {0, "", 2},
                                {9, "Reflectance"},
                                {1, "Echo"},
                                {4, "Height"}}},
                    // The 64-bit types.
                    CopcJsCase{
                        "Format8WithExtraBytes",
                        8,
                        {{10, "Range"}, {5, "Tick"}, {7, "Pulse"}, {6, "Offset"}, {8, "Serial"}}},
                    CopcJsCase{"Format8WithExtraBytesOutOfCore",
                               8,
                               {{10, "Range"}, {0, "", 3}, {8, "Serial"}, {9, "Reflectance"}},
                               12'000,
                               std::size_t{1} << 20}),
    [](const testing::TestParamInfo<CopcJsCase>& test) { return test.param.name; });

}  // namespace
}  // namespace subscan::lod
