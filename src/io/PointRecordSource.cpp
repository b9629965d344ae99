#include "io/PointRecordSource.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/InputFile.h"
#include "io/LasWriter.h"
#include "io/RecordSourceSupport.h"
#include "io/ScanLoader.h"
#include "lod/NodeSource.h"

namespace subscan {

namespace {

constexpr std::string_view kSyntheticSource = "synthetic:";
/// Enough of the start of a file for detectFormat: its text sniffing looks at 4 KiB and must
/// see that the file goes on beyond them.
constexpr std::size_t kSniffedBytes = 4097;
constexpr double kLargestStoredInteger = std::numeric_limits<std::int32_t>::max();
constexpr double kSmallestStoredInteger = std::numeric_limits<std::int32_t>::min();

std::string axisTriple(const glm::dvec3& v) {
    if (v.x == v.y && v.y == v.z) {
        return fmt::format("{:.17g}", v.x);
    }
    return fmt::format("({:.17g}, {:.17g}, {:.17g})", v.x, v.y, v.z);
}

[[noreturn]] void throwIncompatible(const PointRecordSourceInfo& input,
                                    const PointRecordSourceInfo& first, std::string_view what) {
    throw Error(fmt::format("{}: {} {}; index them separately or convert one first", input.name,
                            what, first.name));
}

/// How one input's records become the merged ones.
struct MergedInput {
    std::unique_ptr<PointRecordSource> source;
    std::array<std::int64_t, 3> shift{};  // added to the stored X, Y and Z
    bool asIs = true;                     // same format and no shift: appended unchanged
};

class MergedRecordSource final : public PointRecordSource {
  public:
    MergedRecordSource(std::vector<MergedInput> inputs, PointRecordSourceInfo info)
        : inputs_(std::move(inputs)), info_(std::move(info)) {}

    const PointRecordSourceInfo& info() const override { return info_; }

    std::size_t read(std::vector<std::byte>& records, std::size_t maxPoints) override {
        std::size_t done = 0;
        while (done < maxPoints && current_ < inputs_.size()) {
            MergedInput& input = inputs_[current_];
            std::size_t got = 0;
            if (input.asIs) {
                got = input.source->read(records, maxPoints - done);
            } else {
                scratch_.clear();
                got = input.source->read(scratch_, maxPoints - done);
                append(input, got, records);
            }
            if (got == 0) {
                ++current_;
            }
            done += got;
        }
        return done;
    }

    void rewind() override {
        for (MergedInput& input : inputs_) {
            input.source->rewind();
        }
        current_ = 0;
    }

  private:
    /// Widens the records in scratch_ to the merged format (fields the input lacks are 0) and
    /// moves their coordinates onto the merged grid.
    void append(const MergedInput& input, std::size_t count, std::vector<std::byte>& records) {
        const PointRecordFormat& from = input.source->info().format;
        const std::size_t inLength = from.recordLength();
        const std::size_t inStandard = las14::standardSize(from.pointFormat);
        const std::size_t outLength = info_.format.recordLength();
        const std::size_t outStandard = las14::standardSize(info_.format.pointFormat);
        const std::size_t start = records.size();
        records.resize(start + count * outLength, std::byte{0});
        for (std::size_t i = 0; i < count; ++i) {
            const std::byte* in = scratch_.data() + i * inLength;
            std::byte* out = records.data() + start + i * outLength;
            std::memcpy(out, in, inStandard);
            std::memcpy(out + outStandard, in + inStandard, from.extraBytes);
            for (int axis = 0; axis < 3; ++axis) {
                std::int32_t stored = 0;
                std::memcpy(&stored, in + 4 * axis, 4);
                const std::int64_t moved = stored + input.shift[axis];
                if (moved < kSmallestStoredInteger || moved > kLargestStoredInteger) {
                    throw Error(fmt::format(
                        "{}: a point's {} lies beyond what the merged grid's 32-bit integers hold "
                        "(are its header's bounds stale?)",
                        input.source->info().name, "xyz"[axis]));
                }
                stored = static_cast<std::int32_t>(moved);
                std::memcpy(out + 4 * axis, &stored, 4);
            }
        }
    }

    std::vector<MergedInput> inputs_;
    PointRecordSourceInfo info_;
    std::size_t current_ = 0;
    std::vector<std::byte> scratch_;
};

/// The whole steps between an input's offset and the merged one, per axis; throws when they are
/// not whole.
std::array<std::int64_t, 3> offsetSteps(const PointRecordSourceInfo& input,
                                        const PointRecordSourceInfo& base) {
    std::array<std::int64_t, 3> steps{};
    for (int axis = 0; axis < 3; ++axis) {
        const double scale = base.quantization.scale[axis];
        const double difference = input.quantization.offset[axis] - base.quantization.offset[axis];
        const double whole = std::round(difference / scale);
        // Offsets are decimal numbers held in doubles: two a whole number of steps apart differ
        // from it by the doubles' rounding, a few units of the last place of the larger offset
        // (4 of them allowed), or by far less than a step (a millionth allowed). A coordinate
        // moved by either is the same to far below any scan's precision.
        const double magnitude = std::max(std::abs(input.quantization.offset[axis]),
                                          std::abs(base.quantization.offset[axis]));
        const double tolerance =
            std::max(1e-6 * scale, 4.0 * std::numeric_limits<double>::epsilon() * magnitude);
        if (!(std::abs(difference - whole * scale) <= tolerance)) {
            throwIncompatible(
                input, base,
                fmt::format("its {} offset {:.17g} is not a whole number of steps of {:.17g} from "
                            "the {} offset {:.17g} of",
                            "xyz"[axis], input.quantization.offset[axis], scale, "xyz"[axis],
                            base.quantization.offset[axis]));
        }
        if (!(std::abs(whole) <= 2.0 * kLargestStoredInteger)) {
            throwIncompatible(input, base,
                              fmt::format("its {} offset lies {:.17g} steps of {:.17g}, too far "
                                          "for one grid of 32-bit integers, from that of",
                                          "xyz"[axis], whole, scale));
        }
        steps[axis] = static_cast<std::int64_t>(whole);
    }
    return steps;
}

/// Whether every input's stored coordinates (from its bounds) fit int32 on `base`'s grid.
bool fitsGrid(const std::vector<MergedInput>& inputs, const PointRecordSourceInfo& base) {
    for (const MergedInput& input : inputs) {
        const PointRecordSourceInfo& info = input.source->info();
        for (const glm::dvec3& corner : {info.min, info.max}) {
            const glm::dvec3 stored = (corner - base.quantization.offset) / base.quantization.scale;
            for (int axis = 0; axis < 3; ++axis) {
                if (!(std::abs(stored[axis]) <= kLargestStoredInteger)) {
                    return false;
                }
            }
        }
    }
    return true;
}

/// Puts the inputs that are not LAS on one grid, the finest that holds them all
/// (chooseLasScaling over their combined bounds): each got the finest its own bounds allow,
/// which inputs of other sizes or places cannot share, and no finer grid of 32-bit integers
/// holds them all. LAS inputs keep their own grid.
void shareOneGrid(const std::vector<std::unique_ptr<PointRecordSource>>& sources) {
    std::vector<ConvertedRecordSource*> converted;
    Bounds combined;
    for (const auto& source : sources) {
        if (auto* input = dynamic_cast<ConvertedRecordSource*>(source.get())) {
            converted.push_back(input);
            combined.add(input->bounds().min);
            combined.add(input->bounds().max);
        }
    }
    if (converted.size() < 2) {
        return;
    }
    const LasScaling scaling = chooseLasScaling(combined);
    for (ConvertedRecordSource* input : converted) {
        input->useQuantization({scaling.scale, scaling.offset});
    }
}

void checkCompatible(const PointRecordSourceInfo& input, const PointRecordSourceInfo& first) {
    if (input.quantization.scale != first.quantization.scale) {
        throwIncompatible(input, first,
                          fmt::format("its scale {} differs from the scale {} of",
                                      axisTriple(input.quantization.scale),
                                      axisTriple(first.quantization.scale)));
    }
    if (input.format.extraBytes != first.format.extraBytes ||
        !sameExtraBytesFields(input.format.extraBytesDescriptors,
                              first.format.extraBytesDescriptors)) {
        throwIncompatible(
            input, first,
            fmt::format(
                "its extra bytes ({}: {} bytes) are not the fields ({}: {} bytes) of",
                extraBytesFieldNames(input.format.extraBytesDescriptors), input.format.extraBytes,
                extraBytesFieldNames(first.format.extraBytesDescriptors), first.format.extraBytes));
    }
}

/// An EPT dataset as the records of its tiles: LAZ files of LAS records on the dataset's one
/// scale and offset, merged as `index` merges LAS inputs, so every record passes unchanged.
/// Unlike a render, which leaves out a tile it cannot read, a conversion needs every tile.
class EptRecordSource final : public PointRecordSource {
  public:
    EptRecordSource(const std::filesystem::path& path, unsigned threads) {
        const std::string name = path.string();
        const std::unique_ptr<lod::NodeSource> ept = lod::openEpt(path);
        std::vector<std::unique_ptr<PointRecordSource>> tiles;
        for (const lod::StreamedNode& node : ept->nodes()) {
            const auto fail = [&](const std::string& what) {
                return Error(fmt::format("{}: {}: {}", name, lod::nodeName(node.key), what));
            };
            try {
                tiles.push_back(
                    openLasRecordSource(lod::eptTilePath(ept->info().name, node.key), threads));
            } catch (const Error& error) {
                throw fail(error.what());
            }
            if (tiles.back()->info().pointCount != node.pointCount) {
                throw fail(fmt::format("its tile holds {} points, but the hierarchy says {}",
                                       tiles.back()->info().pointCount, node.pointCount));
            }
        }
        merged_ = mergePointRecordSources(std::move(tiles));
        info_ = merged_->info();
        info_.name = name;
        // Writers of EPT (Entwine, PDAL) give the coordinate system in ept.json; the tiles may
        // carry only GeoTIFF keys, or nothing.
        const bool wktFromDescription = info_.wkt.empty() && !ept->info().wkt.empty();
        if (wktFromDescription) {
            info_.wkt = ept->info().wkt;
        }
        std::vector<std::string> warnings;
        for (const std::string& warning : ept->info().warnings) {
            warnings.push_back(fmt::format("{}: {}", name, warning));
        }
        for (std::string& warning : tileWarnings(ept->info().name, std::move(info_.warnings))) {
            if (!(wktFromDescription && warning.find(kGeoKeysOnly) != std::string::npos)) {
                warnings.push_back(std::move(warning));
            }
        }
        info_.warnings = std::move(warnings);
    }

    const PointRecordSourceInfo& info() const override { return info_; }
    std::size_t read(std::vector<std::byte>& records, std::size_t maxPoints) override {
        return merged_->read(records, maxPoints);
    }
    void rewind() override { merged_->rewind(); }

  private:
    /// One sentence for each thing the tiles warn about: a dataset of thousands of tiles, all
    /// written by one program, would otherwise say the same thousands of times.
    static std::vector<std::string> tileWarnings(const std::filesystem::path& folder,
                                                 std::vector<std::string> warnings) {
        const std::string tiles = (folder / "ept-data").string();
        std::vector<std::string> first;
        std::vector<std::size_t> repeats;
        std::map<std::string, std::size_t> seen;  // what a warning says past its tile's name
        for (std::string& warning : warnings) {
            const std::size_t named =
                warning.starts_with(tiles) ? warning.find(": ", tiles.size()) : std::string::npos;
            const std::string said = named == std::string::npos ? warning : warning.substr(named);
            const auto [at, added] = seen.try_emplace(said, first.size());
            if (added) {
                first.push_back(std::move(warning));
                repeats.push_back(0);
            } else {
                ++repeats[at->second];
            }
        }
        for (std::size_t i = 0; i < first.size(); ++i) {
            if (repeats[i] > 0) {
                first[i] += fmt::format(" (and so do {} more of its tiles)", repeats[i]);
            }
        }
        return first;
    }

    std::unique_ptr<PointRecordSource> merged_;
    PointRecordSourceInfo info_;
};

}  // namespace

std::size_t PointRecordFormat::recordLength() const {
    return las14::standardSize(pointFormat) + extraBytes;
}

std::unique_ptr<PointRecordSource> openPointRecordSource(const std::filesystem::path& path,
                                                         unsigned threads) {
    const std::string name = path.string();
    if (name.starts_with(kSyntheticSource)) {
        return openCloudRecordSource(name);
    }
    if (lod::isEpt(path)) {
        return std::make_unique<EptRecordSource>(path, threads);
    }
    ScanFormat format = ScanFormat::Unknown;
    try {
        const InputFile file(path);
        if (file.size() == 0) {
            throw Error("the file is empty");
        }
        std::vector<std::byte> head(
            static_cast<std::size_t>(std::min<std::uint64_t>(file.size(), kSniffedBytes)));
        file.read(0, head);
        format = detectFormat(head, path);
    } catch (const Error& error) {
        throwNamed(name, error);
    }
    switch (format) {
        case ScanFormat::Las:
            return openLasRecordSource(path, threads);
        case ScanFormat::Xyz:
            return openTextRecordSource(path);
        case ScanFormat::Ply:
            if (auto source = openPlyRecordSource(path)) {
                return source;
            }
            break;
        default:
            break;
    }
    return openCloudRecordSource(name);
}

std::unique_ptr<PointRecordSource> mergePointRecordSources(
    std::vector<std::unique_ptr<PointRecordSource>> sources) {
    if (sources.empty()) {
        throw Error("there are no inputs to merge");
    }
    if (sources.size() == 1) {
        return std::move(sources.front());
    }
    shareOneGrid(sources);
    const PointRecordSourceInfo& first = sources.front()->info();
    PointRecordSourceInfo info;
    std::vector<std::string> names;
    info.format = first.format;
    info.quantization = first.quantization;
    info.min = first.min;
    info.max = first.max;
    info.fileSourceId = first.fileSourceId;
    const PointRecordSourceInfo* wktSource = nullptr;
    const PointRecordSourceInfo* gpsTimeSource = nullptr;
    for (const auto& source : sources) {
        const PointRecordSourceInfo& input = source->info();
        checkCompatible(input, first);
        if (input.standardGpsTime) {
            // One header bit says what every record's GPS time means.
            if (gpsTimeSource != nullptr &&
                input.standardGpsTime != gpsTimeSource->standardGpsTime) {
                const auto kind = [](const PointRecordSourceInfo& s) {
                    return *s.standardGpsTime ? "Adjusted Standard GPS time" : "GPS week seconds";
                };
                throwIncompatible(input, *gpsTimeSource,
                                  fmt::format("its GPS times are {} (global encoding bit 0), "
                                              "but they are {} in",
                                              kind(input), kind(*gpsTimeSource)));
            }
            gpsTimeSource = gpsTimeSource != nullptr ? gpsTimeSource : &input;
        }
        if (input.fileSourceId != info.fileSourceId) {
            info.fileSourceId = 0;
        }
        if (!input.wkt.empty()) {
            if (wktSource != nullptr && input.wkt != wktSource->wkt) {
                throwIncompatible(input, *wktSource,
                                  "its coordinate system (WKT, compared as text) differs from "
                                  "that of");
            }
            wktSource = wktSource != nullptr ? wktSource : &input;
        }
        names.push_back(input.name);
        info.format.pointFormat = std::max(info.format.pointFormat, input.format.pointFormat);
        info.pointCount += input.pointCount;
        info.min = glm::min(info.min, input.min);
        info.max = glm::max(info.max, input.max);
        info.warnings.insert(info.warnings.end(), input.warnings.begin(), input.warnings.end());
    }
    info.name = fmt::format("{}", fmt::join(names, ", "));
    info.wkt = wktSource != nullptr ? wktSource->wkt : std::string();
    info.standardGpsTime = gpsTimeSource != nullptr ? gpsTimeSource->standardGpsTime : std::nullopt;

    std::vector<MergedInput> inputs;
    for (auto& source : sources) {
        const PointRecordSourceInfo& input = source->info();
        // Colour or NIR that an input lacks is 0 in the merged records: LAS has no "absent"
        // value, 0 is what PDAL gives a dimension no input set, and any other constant would
        // be as made up. It is said, because RGB 0 is black: those points show black among
        // coloured ones.
        const int format = input.format.pointFormat;
        if (format == 6 && info.format.pointFormat > 6) {
            info.warnings.push_back(fmt::format(
                "{}: it has no colour; its points get RGB 0 (black) in the merged records",
                input.name));
        }
        if (format < 8 && info.format.pointFormat == 8) {
            info.warnings.push_back(fmt::format(
                "{}: it has no near infrared; its points get NIR 0 in the merged records",
                input.name));
        }
        inputs.push_back({std::move(source), {}, format == info.format.pointFormat});
    }
    // The grid is one input's offset: the first whose grid holds every input's coordinates.
    const auto base = std::find_if(inputs.begin(), inputs.end(), [&](const MergedInput& input) {
        return fitsGrid(inputs, input.source->info());
    });
    if (base == inputs.end()) {
        throw Error(fmt::format(
            "{}: the inputs lie too far apart for one grid of 32-bit integers at scale {}; index "
            "them separately",
            info.name, axisTriple(info.quantization.scale)));
    }
    info.quantization.offset = base->source->info().quantization.offset;
    for (MergedInput& input : inputs) {
        input.shift = offsetSteps(input.source->info(), base->source->info());
        input.asIs = input.asIs && input.shift == std::array<std::int64_t, 3>{};
    }
    return std::make_unique<MergedRecordSource>(std::move(inputs), std::move(info));
}

}  // namespace subscan
