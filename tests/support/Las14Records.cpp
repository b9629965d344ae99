#include "support/Las14Records.h"

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>

namespace subscan::test {

namespace {

// LAS 1.4 R15, tables 3 and 15-17: where the header fields and the record fields lie.
constexpr std::size_t kHeaderSize = 375;
constexpr std::size_t kPointBytes = 30;  // formats 6-10 start with these

/// The fields of one record, before they are stored.
struct Las14Point {
    std::int32_t x = 0, y = 0, z = 0;
    std::uint16_t intensity = 0;
    std::uint8_t returnNumber = 1, numberOfReturns = 1;
    std::uint8_t classificationFlags = 0, scannerChannel = 0;
    bool scanDirection = false, edge = false;
    std::uint8_t classification = 0, userData = 0;
    std::int16_t scanAngle = 0;
    std::uint16_t pointSourceId = 0;
    std::uint64_t gpsTimeBits = 0;
    std::array<std::uint16_t, 4> rgbNir{};
    std::vector<std::uint8_t> extra;
};

template <class T>
void put(std::byte* p, T value) {
    std::memcpy(p, &value, sizeof(T));  // the tests run on little-endian hosts (LAS's order)
}

void storePoint(const Las14Point& point, int pointFormat, std::byte* p) {
    put(p, point.x);
    put(p + 4, point.y);
    put(p + 8, point.z);
    put(p + 12, point.intensity);
    put(p + 14, static_cast<std::uint8_t>(point.returnNumber | (point.numberOfReturns << 4)));
    put(p + 15,
        static_cast<std::uint8_t>(point.classificationFlags | (point.scannerChannel << 4) |
                                  (point.scanDirection ? 0x40 : 0) | (point.edge ? 0x80 : 0)));
    put(p + 16, point.classification);
    put(p + 17, point.userData);
    put(p + 18, point.scanAngle);
    put(p + 20, point.pointSourceId);
    put(p + 22, point.gpsTimeBits);
    std::size_t at = kPointBytes;
    const std::size_t colours = pointFormat == 6 ? 0 : (pointFormat == 7 ? 3 : 4);
    for (std::size_t c = 0; c < colours; ++c, at += 2) {
        put(p + at, point.rgbNir[c]);
    }
    if (!point.extra.empty()) {
        std::memcpy(p + at, point.extra.data(), point.extra.size());
    }
}

enum class RunKind { Quiet, Busy, Pulses, Extremes, FlightLines, OneField };
constexpr int kRunKinds = 6;

class Generator {
  public:
    Generator(const Las14RecordOptions& options) : options_(options), random_(options.seed) {
        point_.extra.assign(options.extraBytes, 0);
        for (std::size_t line = 0; line < lines_.size(); ++line) {
            // Flight lines hours apart: their times differ by far more than 32 bits of a double.
            lines_[line] = 300000.0 + 3600.0 * static_cast<double>(line);
        }
        point_.gpsTimeBits = std::bit_cast<std::uint64_t>(lines_[0]);
    }

    Las14Point next() {
        if (runLeft_ == 0) {
            kind_ = static_cast<RunKind>(uniform(0, kRunKinds - 1));
            runLeft_ = static_cast<int>(uniform(1, 200));
            field_ = static_cast<int>(uniform(0, 11));
        }
        --runLeft_;
        walkCoordinates();
        switch (kind_) {
            case RunKind::Quiet:
                break;
            case RunKind::Busy:
                for (int field = 0; field < 12; ++field) {
                    if (chance(2)) {
                        changeField(field);
                    }
                }
                break;
            case RunKind::Pulses:
                nextReturn();
                break;
            case RunKind::Extremes:
                extremes();
                break;
            case RunKind::FlightLines:
                point_.gpsTimeBits = std::bit_cast<std::uint64_t>(nextLineTime());
                break;
            case RunKind::OneField:
                changeField(field_);
                break;
        }
        return point_;
    }

  private:
    std::uint64_t uniform(std::uint64_t low, std::uint64_t high) {
        return std::uniform_int_distribution<std::uint64_t>(low, high)(random_);
    }
    bool chance(std::uint64_t oneIn) { return uniform(1, oneIn) == 1; }
    template <class T>
    T anyValue() {
        return static_cast<T>(uniform(0, std::numeric_limits<std::make_unsigned_t<T>>::max()));
    }

    void walkCoordinates() {
        // Small steps mostly, so that the medians and k contexts adapt; sometimes a long one.
        const auto step = [&] {
            return chance(20) ? anyValue<std::int32_t>()
                              : static_cast<std::int32_t>(uniform(0, 400)) - 200;
        };
        const auto wrapAdd = [](std::int32_t a, std::int32_t b) {
            return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) +
                                             static_cast<std::uint32_t>(b));
        };
        point_.x = wrapAdd(point_.x, step());
        point_.y = wrapAdd(point_.y, step());
        if (!chance(4)) {
            point_.z = wrapAdd(point_.z, step());
        }
    }

    void changeField(int field) {
        Las14Point& p = point_;
        switch (field) {
            case 0:
                p.intensity = anyValue<std::uint16_t>();
                break;
            case 1:
                p.numberOfReturns = static_cast<std::uint8_t>(uniform(0, 15));
                p.returnNumber = static_cast<std::uint8_t>(uniform(0, 15));
                break;
            case 2:
                p.classificationFlags = static_cast<std::uint8_t>(uniform(0, 15));
                p.scanDirection = chance(2);
                p.edge = chance(2);
                break;
            case 3:
                if (options_.allChannels) {
                    p.scannerChannel = static_cast<std::uint8_t>(uniform(0, 3));
                }
                break;
            case 4:
                p.classification = anyValue<std::uint8_t>();
                break;
            case 5:
                p.userData = anyValue<std::uint8_t>();
                break;
            case 6:
                p.scanAngle = anyValue<std::int16_t>();
                break;
            case 7:
                p.pointSourceId = anyValue<std::uint16_t>();
                break;
            case 8:
                p.gpsTimeBits = std::bit_cast<std::uint64_t>(nextLineTime());
                break;
            case 9:
                changeColour();
                break;
            case 10:
                p.rgbNir[3] = anyValue<std::uint16_t>();
                break;
            default:
                for (std::uint8_t& byte : p.extra) {
                    if (chance(2)) {
                        byte = anyValue<std::uint8_t>();
                    }
                }
                break;
        }
    }

    void changeColour() {
        std::array<std::uint16_t, 4>& c = point_.rgbNir;
        if (chance(4)) {
            c[0] = anyValue<std::uint16_t>();
            c[1] = c[0];
            c[2] = c[0];  // grey: green and blue are not coded
        } else if (chance(2)) {
            for (int i = 0; i < 3; ++i) {  // a nearby colour: small byte differences
                c[i] = static_cast<std::uint16_t>(c[i] + uniform(0, 6) - 3);
            }
        } else {
            for (int i = 0; i < 3; ++i) {
                c[i] = anyValue<std::uint16_t>();
            }
        }
    }

    /// The next return of a pulse; a new pulse (return 1) gets a new time.
    void nextReturn() {
        Las14Point& p = point_;
        if (p.returnNumber >= p.numberOfReturns || p.numberOfReturns > 7) {
            p.numberOfReturns = static_cast<std::uint8_t>(uniform(1, 7));
            p.returnNumber = 1;
            p.gpsTimeBits = std::bit_cast<std::uint64_t>(nextLineTime());
        } else {
            ++p.returnNumber;
        }
        p.intensity = static_cast<std::uint16_t>(p.intensity + uniform(0, 100));
    }

    /// The next time of a random flight line: mostly the line's regular step, sometimes a
    /// multiple of it, a step back, or no step at all.
    double nextLineTime() {
        const std::size_t line = chance(3) ? uniform(0, lines_.size() - 1) : currentLine_;
        currentLine_ = line;
        const double step = 1e-5 * static_cast<double>(line + 1);
        double steps = 1.0;
        if (chance(4)) {
            steps = static_cast<double>(uniform(0, 1200)) - 100.0;
        }
        lines_[line] += steps * step;
        return lines_[line];
    }

    void extremes() {
        Las14Point& p = point_;
        const auto pick = [&](auto a, auto b, auto c) {
            return chance(3) ? a : (chance(2) ? b : c);
        };
        p.x = pick(std::numeric_limits<std::int32_t>::min(),
                   std::numeric_limits<std::int32_t>::max(), 0);
        p.y = pick(std::numeric_limits<std::int32_t>::max(),
                   std::numeric_limits<std::int32_t>::min(), -1);
        p.z = pick(0, std::numeric_limits<std::int32_t>::min(),
                   std::numeric_limits<std::int32_t>::max());
        p.intensity = pick(std::uint16_t{0}, std::uint16_t{65535}, std::uint16_t{32768});
        p.scanAngle = pick(std::int16_t{-32768}, std::int16_t{32767}, std::int16_t{0});
        p.pointSourceId = pick(std::uint16_t{65535}, std::uint16_t{0}, std::uint16_t{1});
        p.gpsTimeBits = pick(
            std::bit_cast<std::uint64_t>(-0.0), std::bit_cast<std::uint64_t>(0.0),
            chance(2) ? std::bit_cast<std::uint64_t>(std::nan("")) : anyValue<std::uint64_t>());
        p.rgbNir = pick(std::array<std::uint16_t, 4>{65535, 0, 65535, 0},
                        std::array<std::uint16_t, 4>{0, 0, 0, 65535},
                        std::array<std::uint16_t, 4>{255, 256, 65280, 255});
        p.numberOfReturns = pick(std::uint8_t{15}, std::uint8_t{0}, std::uint8_t{1});
        p.returnNumber = pick(std::uint8_t{0}, std::uint8_t{15}, std::uint8_t{14});
    }

    Las14RecordOptions options_;
    std::mt19937_64 random_;
    Las14Point point_;
    RunKind kind_ = RunKind::Quiet;
    int runLeft_ = 0;
    int field_ = 0;
    std::array<double, 5> lines_{};  // one flight line more than the coder's four sequences
    std::size_t currentLine_ = 0;
};

}  // namespace

void PrintTo(const Las14Format& format, std::ostream* out) {
    *out << "format " << format.pointFormat << " with " << format.extraBytes << " extra bytes";
}

std::string las14FormatName(const Las14Format& format) {
    return "Format" + std::to_string(format.pointFormat) + "With" +
           std::to_string(format.extraBytes) + "ExtraBytes";
}

std::size_t las14RecordLength(int pointFormat, std::size_t extraBytes) {
    switch (pointFormat) {
        case 6:
            return kPointBytes + extraBytes;
        case 7:
            return kPointBytes + 6 + extraBytes;
        case 8:
            return kPointBytes + 8 + extraBytes;
        default:
            throw std::invalid_argument("the test records are of point formats 6, 7 and 8");
    }
}

std::vector<std::byte> randomLas14Records(const Las14RecordOptions& options, std::size_t count) {
    const std::size_t length = las14RecordLength(options.pointFormat, options.extraBytes);
    std::vector<std::byte> records(count * length);
    Generator generator(options);
    for (std::size_t i = 0; i < count; ++i) {
        storePoint(generator.next(), options.pointFormat, records.data() + i * length);
    }
    return records;
}

std::vector<std::byte> las14Header(int pointFormat, std::size_t recordLength,
                                   std::uint64_t pointCount) {
    std::vector<std::byte> header(kHeaderSize, std::byte{0});
    std::memcpy(header.data(), "LASF", 4);
    put<std::uint16_t>(header.data() + 6, 1 << 4);  // global encoding: WKT coordinate system
    header[24] = std::byte{1};
    header[25] = std::byte{4};
    std::memcpy(header.data() + 58, "subscan tests", 13);
    put<std::uint16_t>(header.data() + 94, kHeaderSize);
    put<std::uint32_t>(header.data() + 96, kHeaderSize);
    header[104] = static_cast<std::byte>(pointFormat);
    put(header.data() + 105, static_cast<std::uint16_t>(recordLength));
    for (int axis = 0; axis < 3; ++axis) {
        put(header.data() + 131 + 8 * axis, 0.001);
    }
    put(header.data() + 155, 1000.0);
    put(header.data() + 163, 2000.0);
    put(header.data() + 247, pointCount);
    return header;
}

}  // namespace subscan::test
