#include "io/laz/ItemCoding.h"

#include "core/Error.h"

namespace subscan::laz {

void Median5::add(std::int32_t v) {
    std::array<std::int32_t, 5>& s = values_;
    if (replaceHigh_) {
        if (v < s[2]) {
            s[4] = s[3];
            s[3] = s[2];
            if (v < s[0]) {
                s[2] = s[1];
                s[1] = s[0];
                s[0] = v;
            } else if (v < s[1]) {
                s[2] = s[1];
                s[1] = v;
            } else {
                s[2] = v;
            }
        } else {
            if (v < s[3]) {
                s[4] = s[3];
                s[3] = v;
            } else {
                s[4] = v;
            }
            replaceHigh_ = false;
        }
    } else {
        if (s[2] < v) {
            s[0] = s[1];
            s[1] = s[2];
            if (s[4] < v) {
                s[2] = s[3];
                s[3] = s[4];
                s[4] = v;
            } else if (s[3] < v) {
                s[2] = s[3];
                s[3] = v;
            } else {
                s[2] = v;
            }
        } else {
            if (s[1] < v) {
                s[0] = s[1];
                s[1] = v;
            } else {
                s[0] = v;
            }
            replaceHigh_ = true;
        }
    }
}

namespace {
// A corrupt stream could switch sequences without end; a valid one switches once per point.
constexpr int kMaxSequenceSwitches = 4;
}  // namespace

void GpsTimeDecoder::readFullTime(ArithmeticDecoder& decoder) {
    GpsTimeSequences<IntegerDecompressor>& s = state_;
    s.next = (s.next + 1) & 3;
    const auto high = static_cast<std::uint32_t>(s.integers.decompress(
        decoder, static_cast<std::int32_t>(static_cast<std::uint64_t>(s.times[s.last]) >> 32), 8));
    s.times[s.next] =
        static_cast<std::int64_t>((static_cast<std::uint64_t>(high) << 32) | decoder.readInt());
    s.last = s.next;
    s.lastDiffs[s.last] = 0;
    s.extremeCounters[s.last] = 0;
}

void GpsTimeDecoder::decode(ArithmeticDecoder& decoder) {
    GpsTimeSequences<IntegerDecompressor>& s = state_;
    for (int switches = 0; switches <= kMaxSequenceSwitches; ++switches) {
        if (s.lastDiffs[s.last] == 0) {
            std::uint32_t code = decoder.decodeSymbol(s.zeroDiffModel);
            if (pointwise_) {
                if (code == 0) {
                    return;  // unchanged
                }
                --code;
            }
            if (code == 0) {  // a difference that fits 32 bits
                s.lastDiffs[s.last] = s.integers.decompress(decoder, 0, 0);
                s.times[s.last] += s.lastDiffs[s.last];
                s.extremeCounters[s.last] = 0;
                return;
            }
            if (code == 1) {
                readFullTime(decoder);
                return;
            }
            s.last = (s.last + code - 1) & 3;
            continue;
        }

        std::uint32_t multi = decoder.decodeSymbol(s.multiModel);
        const std::int32_t lastDiff = s.lastDiffs[s.last];
        if (multi == 1) {
            s.times[s.last] += s.integers.decompress(decoder, lastDiff, 1);
            s.extremeCounters[s.last] = 0;
            return;
        }
        if (multi < kGpsTimeFullCode) {
            std::int32_t diff;
            if (multi == 0) {
                diff = s.integers.decompress(decoder, 0, 7);
                s.countExtreme(diff);
            } else if (multi < static_cast<std::uint32_t>(kGpsTimeMaxMultiple)) {
                diff = s.integers.decompress(
                    decoder, wrappingMultiply(static_cast<std::int32_t>(multi), lastDiff),
                    multi < 10 ? 2 : 3);
            } else if (multi == static_cast<std::uint32_t>(kGpsTimeMaxMultiple)) {
                diff = s.integers.decompress(decoder,
                                             wrappingMultiply(kGpsTimeMaxMultiple, lastDiff), 4);
                s.countExtreme(diff);
            } else {
                const std::int32_t negative =
                    kGpsTimeMaxMultiple - static_cast<std::int32_t>(multi);
                if (negative > kGpsTimeMinMultiple) {
                    diff = s.integers.decompress(decoder, wrappingMultiply(negative, lastDiff), 5);
                } else {
                    diff = s.integers.decompress(
                        decoder, wrappingMultiply(kGpsTimeMinMultiple, lastDiff), 6);
                    s.countExtreme(diff);
                }
            }
            s.times[s.last] += diff;
            return;
        }
        if (pointwise_) {
            if (multi == kGpsTimeFullCode) {
                return;  // v2's "unchanged" sits where v3 has the full time
            }
            --multi;
        }
        if (multi == kGpsTimeFullCode) {
            readFullTime(decoder);
            return;
        }
        s.last = (s.last + multi - kGpsTimeFullCode) & 3;
    }
    throw Error("the LAZ point data is corrupt (GPS time sequences switch without end)");
}

void RgbModels::reset() {
    changedBytes.reset();
    for (SymbolModel& model : differences) {
        model.reset();
    }
}

std::array<std::uint16_t, 3> decodeRgb(ArithmeticDecoder& decoder, RgbModels& models,
                                       const std::array<std::uint16_t, 3>& last) {
    const std::uint32_t changed = decoder.decodeSymbol(models.changedBytes);
    const auto low = [](std::uint16_t v) { return static_cast<std::int32_t>(v & 0xFF); };
    const auto high = [](std::uint16_t v) { return static_cast<std::int32_t>(v >> 8); };
    // Byte `index` of the colour: the last value plus a decoded difference to `prediction`.
    const auto byteAt = [&](std::uint32_t bit, std::int32_t prediction, std::int32_t unchanged) {
        if ((changed & (1u << bit)) == 0) {
            return unchanged;
        }
        const auto difference = static_cast<std::int32_t>(
            static_cast<std::uint8_t>(decoder.decodeSymbol(models.differences[bit])));
        return static_cast<std::int32_t>(foldByte(difference + prediction));
    };
    std::array<std::uint16_t, 3> rgb{};
    const std::int32_t redLow = byteAt(0, low(last[0]), low(last[0]));
    const std::int32_t redHigh = byteAt(1, high(last[0]), high(last[0]));
    rgb[0] = static_cast<std::uint16_t>(redLow | (redHigh << 8));
    if ((changed & (1u << 6)) == 0) {  // grey: green and blue equal red
        rgb[1] = rgb[0];
        rgb[2] = rgb[0];
        return rgb;
    }
    std::int32_t diff = redLow - low(last[0]);
    const std::int32_t greenLow = byteAt(2, clampByte(diff + low(last[1])), low(last[1]));
    diff = (diff + greenLow - low(last[1])) / 2;
    const std::int32_t blueLow = byteAt(4, clampByte(diff + low(last[2])), low(last[2]));
    diff = redHigh - high(last[0]);
    const std::int32_t greenHigh = byteAt(3, clampByte(diff + high(last[1])), high(last[1]));
    diff = (diff + greenHigh - high(last[1])) / 2;
    const std::int32_t blueHigh = byteAt(5, clampByte(diff + high(last[2])), high(last[2]));
    rgb[1] = static_cast<std::uint16_t>(greenLow | (greenHigh << 8));
    rgb[2] = static_cast<std::uint16_t>(blueLow | (blueHigh << 8));
    return rgb;
}

}  // namespace subscan::laz
