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
// Multiples of the last difference run from -10 to 500 (LASzip's GPS time coder).
constexpr std::int32_t kMaxMultiple = 500;
constexpr std::int32_t kMinMultiple = -10;
// Symbol of "a full new time" in the multiple model; the symbols after it switch sequences.
constexpr std::uint32_t kFullTimeCode = kMaxMultiple - kMinMultiple + 1;  // 511
// A corrupt stream could switch sequences without end; a valid one switches once per point.
constexpr int kMaxSequenceSwitches = 4;
}  // namespace

GpsTimeDecoder::GpsTimeDecoder(bool pointwise)
    : pointwise_(pointwise),
      multiModel_(pointwise ? 516 : 515),
      zeroDiffModel_(pointwise ? 6 : 5) {}

void GpsTimeDecoder::reset(std::uint64_t firstTimeBits) {
    multiModel_.reset();
    zeroDiffModel_.reset();
    integers_.reset();
    last_ = 0;
    next_ = 0;
    times_ = {static_cast<std::int64_t>(firstTimeBits), 0, 0, 0};
    lastDiffs_ = {};
    extremeCounters_ = {};
}

void GpsTimeDecoder::readFullTime(ArithmeticDecoder& decoder) {
    next_ = (next_ + 1) & 3;
    const auto high = static_cast<std::uint32_t>(integers_.decompress(
        decoder, static_cast<std::int32_t>(static_cast<std::uint64_t>(times_[last_]) >> 32), 8));
    times_[next_] =
        static_cast<std::int64_t>((static_cast<std::uint64_t>(high) << 32) | decoder.readInt());
    last_ = next_;
    lastDiffs_[last_] = 0;
    extremeCounters_[last_] = 0;
}

void GpsTimeDecoder::decode(ArithmeticDecoder& decoder) {
    for (int switches = 0; switches <= kMaxSequenceSwitches; ++switches) {
        if (lastDiffs_[last_] == 0) {
            std::uint32_t code = decoder.decodeSymbol(zeroDiffModel_);
            if (pointwise_) {
                if (code == 0) {
                    return;  // unchanged
                }
                --code;
            }
            if (code == 0) {  // a difference that fits 32 bits
                lastDiffs_[last_] = integers_.decompress(decoder, 0, 0);
                times_[last_] += lastDiffs_[last_];
                extremeCounters_[last_] = 0;
                return;
            }
            if (code == 1) {
                readFullTime(decoder);
                return;
            }
            last_ = (last_ + code - 1) & 3;
            continue;
        }

        std::uint32_t multi = decoder.decodeSymbol(multiModel_);
        const std::int32_t lastDiff = lastDiffs_[last_];
        // An extreme multiple (0, the largest or the most negative) four times in a row becomes
        // the sequence's new difference.
        const auto countExtreme = [&](std::int32_t diff) {
            if (++extremeCounters_[last_] > 3) {
                lastDiffs_[last_] = diff;
                extremeCounters_[last_] = 0;
            }
        };
        if (multi == 1) {
            times_[last_] += integers_.decompress(decoder, lastDiff, 1);
            extremeCounters_[last_] = 0;
            return;
        }
        if (multi < kFullTimeCode) {
            std::int32_t diff;
            if (multi == 0) {
                diff = integers_.decompress(decoder, 0, 7);
                countExtreme(diff);
            } else if (multi < static_cast<std::uint32_t>(kMaxMultiple)) {
                diff = integers_.decompress(
                    decoder, wrappingMultiply(static_cast<std::int32_t>(multi), lastDiff),
                    multi < 10 ? 2 : 3);
            } else if (multi == static_cast<std::uint32_t>(kMaxMultiple)) {
                diff = integers_.decompress(decoder, wrappingMultiply(kMaxMultiple, lastDiff), 4);
                countExtreme(diff);
            } else {
                const std::int32_t negative = kMaxMultiple - static_cast<std::int32_t>(multi);
                if (negative > kMinMultiple) {
                    diff = integers_.decompress(decoder, wrappingMultiply(negative, lastDiff), 5);
                } else {
                    diff =
                        integers_.decompress(decoder, wrappingMultiply(kMinMultiple, lastDiff), 6);
                    countExtreme(diff);
                }
            }
            times_[last_] += diff;
            return;
        }
        if (pointwise_) {
            if (multi == kFullTimeCode) {
                return;  // v2's "unchanged" sits where v3 has the full time
            }
            --multi;
        }
        if (multi == kFullTimeCode) {
            readFullTime(decoder);
            return;
        }
        last_ = (last_ + multi - kFullTimeCode) & 3;
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
