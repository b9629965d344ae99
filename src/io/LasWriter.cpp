#include "io/LasWriter.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/AtomicFile.h"
#include "io/WriterSupport.h"

namespace subscan {

namespace {

/// Candidate scales, finest first. Literals, so that each is the double nearest its power of ten
/// (other tools then print 1e-06, not 9.9999999999999995e-07).
constexpr std::array kScales{1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1,
                             1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7};
constexpr double kLargestStored = std::numeric_limits<std::int32_t>::max();

// LAS 1.2 (ASPRS, 2008), table 4: the public header block, and tables 7 and 9: point data
// record formats 0 and 2.
constexpr std::size_t kHeaderSize = 227;
constexpr std::size_t kIdentifierSize = 32;  // system identifier and generating software
constexpr std::size_t kReturnCounts = 5;     // number of points by return
constexpr std::size_t kFormat0Size = 20;
constexpr std::size_t kFormat2Size = 26;
/// Return number 1 (bits 0-2) of 1 (number of returns, bits 3-5): a converted cloud knows no
/// returns, and every reader expects each point to be one.
constexpr std::uint8_t kFirstOfOneReturn = 1 | (1 << 3);
constexpr std::string_view kSubscan = "subscan";

static_assert(kMaxPoints <= std::numeric_limits<std::uint32_t>::max(),
              "LAS 1.2 counts points in 32 bits");

/// Appends `text` padded with NULs to `size` bytes.
void appendFixedString(std::string& out, std::string_view text, std::size_t size) {
    out.append(text.substr(0, size));
    out.append(size - std::min(text.size(), size), '\0');
}

/// Today as day of the year (1 = January 1st) and year, in UTC as the format asks.
std::array<std::uint16_t, 2> creationDate() {
    using namespace std::chrono;
    const sys_days today = floor<days>(system_clock::now());
    const year_month_day date(today);
    const sys_days newYear = date.year() / January / 1;
    return {static_cast<std::uint16_t>((today - newYear).count() + 1),
            static_cast<std::uint16_t>(static_cast<int>(date.year()))};
}

std::uint16_t toIntensity(float value) {
    if (!(value > 0.0f)) {
        return 0;  // also NaN
    }
    return static_cast<std::uint16_t>(std::lround(std::min(value, 65535.0f)));
}

using StoredPosition = std::array<std::int32_t, 3>;

class Quantizer {
  public:
    explicit Quantizer(const LasScaling& scaling) : scaling_(scaling) {}

    /// chooseLasScaling keeps every coordinate within the bounds it was given inside int32.
    StoredPosition stored(const glm::dvec3& position) const {
        StoredPosition values;
        for (int axis = 0; axis < 3; ++axis) {
            const double steps = (position[axis] - scaling_.offset[axis]) / scaling_.scale[axis];
            values[axis] = static_cast<std::int32_t>(std::llround(steps));
        }
        return values;
    }
    /// What a reader computes from the stored values.
    glm::dvec3 decoded(const StoredPosition& stored) const {
        return glm::dvec3(stored[0], stored[1], stored[2]) * scaling_.scale + scaling_.offset;
    }

  private:
    LasScaling scaling_;
};

std::string header(const PointCloud& cloud, const LasScaling& scaling, const Bounds& stored) {
    const bool rgb = cloud.hasColors();
    std::string out = "LASF";
    out.append(2 + 2 + 16, '\0');  // file source id, global encoding, project GUID
    out.push_back(1);              // version 1.2
    out.push_back(2);
    appendFixedString(out, kSubscan, kIdentifierSize);  // system identifier
    appendFixedString(out, kSubscan, kIdentifierSize);  // generating software
    for (const std::uint16_t value : creationDate()) {
        appendLittleEndian(out, value);
    }
    appendLittleEndian(out, static_cast<std::uint16_t>(kHeaderSize));
    appendLittleEndian(out, static_cast<std::uint32_t>(kHeaderSize));  // offset to point data
    appendLittleEndian(out, std::uint32_t{0});                         // no variable length records
    appendLittleEndian(out, static_cast<std::uint8_t>(rgb ? 2 : 0));
    appendLittleEndian(out, static_cast<std::uint16_t>(rgb ? kFormat2Size : kFormat0Size));
    const auto count = static_cast<std::uint32_t>(cloud.size());
    appendLittleEndian(out, count);
    appendLittleEndian(out, count);  // all of them first returns
    for (std::size_t r = 1; r < kReturnCounts; ++r) {
        appendLittleEndian(out, std::uint32_t{0});
    }
    for (const glm::dvec3& triple : {scaling.scale, scaling.offset}) {
        for (int axis = 0; axis < 3; ++axis) {
            appendLittleEndian(out, triple[axis]);
        }
    }
    for (int axis = 0; axis < 3; ++axis) {
        // An empty cloud has no bounds: zeros.
        appendLittleEndian(out, stored.empty() ? 0.0 : stored.max[axis]);
        appendLittleEndian(out, stored.empty() ? 0.0 : stored.min[axis]);
    }
    return out;
}

}  // namespace

std::uint8_t lasClassification(std::uint8_t code) {
    return code <= kLargestLegacyClass ? code : kUnclassified;
}

LasScaling chooseLasScaling(const Bounds& bounds) {
    LasScaling scaling;
    if (bounds.empty()) {
        scaling.scale = glm::dvec3(kScales.front());
        return scaling;
    }
    for (int axis = 0; axis < 3; ++axis) {
        const double low = bounds.min[axis];
        const double high = bounds.max[axis];
        const double unit = std::pow(10.0, std::floor(std::log10(std::max(high - low, 1.0))));
        const double offset = std::floor(low / unit) * unit;
        // The largest distance from the offset: (low - offset) may be a rounding below zero.
        const double reach = std::max(high - offset, offset - low);
        const auto fits = std::find_if(kScales.begin(), kScales.end(), [&](double scale) {
            return reach / scale <= kLargestStored;
        });
        if (fits == kScales.end()) {
            throw Error(fmt::format(
                "its coordinates reach {:.6g} from the LAS offset along {}, more than 32-bit "
                "integers can hold even at a scale of {:g}",
                reach, "xyz"[axis], kScales.back()));
        }
        scaling.scale[axis] = *fits;
        scaling.offset[axis] = offset;
    }
    return scaling;
}

void writeLas(const std::filesystem::path& path, const PointCloud& cloud) {
    // The stored bounds must be those of the coordinates written (fileCoordinates), not the
    // cloud's exact ones from its file, which they miss by float rounding where no residuals
    // are kept.
    Bounds bounds;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        bounds.add(cloud.fileCoordinates(i));
    }
    LasScaling scaling;
    try {
        scaling = chooseLasScaling(bounds);
    } catch (const Error& error) {
        throw Error(fmt::format("{}: cannot write it as LAS: {}", path.string(), error.what()));
    }
    const Quantizer quantizer(scaling);
    Bounds stored;
    if (!bounds.empty()) {
        // Rounding is monotonic, so the extreme coordinates give the extreme stored values.
        stored.add(quantizer.decoded(quantizer.stored(bounds.min)));
        stored.add(quantizer.decoded(quantizer.stored(bounds.max)));
    }

    writeFileAtomically(path, [&](std::ostream& stream) {
        ChunkedOutput out(stream);
        out.buffer() = header(cloud, scaling, stored);
        for (std::size_t i = 0; i < cloud.size(); ++i) {
            for (const std::int32_t value : quantizer.stored(cloud.fileCoordinates(i))) {
                out.append(value);
            }
            out.append(cloud.hasIntensities() ? toIntensity(cloud.intensities[i])
                                              : std::uint16_t{0});
            out.append(kFirstOfOneReturn);
            out.append(cloud.hasClassifications() ? lasClassification(cloud.classifications[i])
                                                  : std::uint8_t{0});  // never classified
            out.append(std::int8_t{0});                                // scan angle rank
            out.append(std::uint8_t{0});                               // user data
            out.append(std::uint16_t{0});                              // point source id
            if (cloud.hasColors()) {
                // 8-bit c as 16-bit c * 257 spans 0..65535 and maps back to c exactly.
                const Rgba8& color = cloud.colors[i];
                for (const std::uint8_t channel : {color.r, color.g, color.b}) {
                    out.append(static_cast<std::uint16_t>(channel * 257));
                }
            }
            out.flushIfFull();
        }
        out.flush();
    });
}

}  // namespace subscan
