#include "io/laz/ItemEncoding.h"

#include <algorithm>

namespace subscan::laz {

namespace {

/// The sequence (1 to 3 after `last`) whose last time is within 32 bits of `time`, or 0.
std::uint32_t sequenceWithin32Bits(const GpsTimeSequences<IntegerCompressor>& s,
                                   std::int64_t time) {
    for (std::uint32_t step = 1; step < 4; ++step) {
        const auto diff =
            static_cast<std::int64_t>(static_cast<std::uint64_t>(time) -
                                      static_cast<std::uint64_t>(s.times[(s.last + step) & 3]));
        if (diff == static_cast<std::int32_t>(diff)) {
            return step;
        }
    }
    return 0;
}

/// LASzip's multiple of the last difference: the float quotient rounded half away from zero as
/// I32_QUANTIZE does (adding 0.5f, then truncating; laz-perf's std::round differs only for
/// +-0.49999997, the float just below one half, where the sum rounds up to 1). Quotients beyond
/// the coded multiples (-10..500) are clamped first: they code alike, and the conversion of a
/// float outside int32 is undefined (LASzip gets INT_MIN there on x86, coding -10 where this
/// codes 500). Any multiple decodes to the same time; only the bytes would differ.
std::int32_t nearestMultiple(std::int32_t diff, std::int32_t lastDiff) {
    const float quotient = std::clamp(static_cast<float>(diff) / static_cast<float>(lastDiff),
                                      2.0f * kGpsTimeMinMultiple, 2.0f * kGpsTimeMaxMultiple);
    return quotient >= 0.0f ? static_cast<std::int32_t>(quotient + 0.5f)
                            : static_cast<std::int32_t>(quotient - 0.5f);
}

}  // namespace

void GpsTimeEncoder::encode(ArithmeticEncoder& encoder, std::uint64_t timeBits) {
    GpsTimeSequences<IntegerCompressor>& s = state_;
    const auto time = static_cast<std::int64_t>(timeBits);
    // A switch to another sequence lands on one whose time is within 32 bits, so this ends by
    // the second pass.
    for (;;) {
        const auto diff64 = static_cast<std::int64_t>(static_cast<std::uint64_t>(time) -
                                                      static_cast<std::uint64_t>(s.times[s.last]));
        const auto diff = static_cast<std::int32_t>(diff64);
        const bool fits = diff64 == diff;
        const bool noDifference = s.lastDiffs[s.last] == 0;
        if (fits) {
            if (noDifference) {
                encoder.encodeSymbol(s.zeroDiffModel, 0);
                s.integers.compress(encoder, 0, diff, 0);
                s.lastDiffs[s.last] = diff;
                s.extremeCounters[s.last] = 0;
            } else {
                writeMultiple(encoder, diff);
            }
            s.times[s.last] = time;
            return;
        }
        // Too far from this sequence: another one, or a full new time starting a sequence.
        const std::uint32_t step = sequenceWithin32Bits(s, time);
        if (step == 0) {
            if (noDifference) {
                encoder.encodeSymbol(s.zeroDiffModel, 1);
            } else {
                encoder.encodeSymbol(s.multiModel, kGpsTimeFullCode);
            }
            writeFullTime(encoder, time);
            return;
        }
        if (noDifference) {
            encoder.encodeSymbol(s.zeroDiffModel, step + 1);
        } else {
            encoder.encodeSymbol(s.multiModel, kGpsTimeFullCode + step);
        }
        s.last = (s.last + step) & 3;
    }
}

void GpsTimeEncoder::writeFullTime(ArithmeticEncoder& encoder, std::int64_t time) {
    GpsTimeSequences<IntegerCompressor>& s = state_;
    const auto bits = static_cast<std::uint64_t>(time);
    s.integers.compress(
        encoder, static_cast<std::int32_t>(static_cast<std::uint64_t>(s.times[s.last]) >> 32),
        static_cast<std::int32_t>(bits >> 32), 8);
    encoder.writeInt(static_cast<std::uint32_t>(bits));
    s.next = (s.next + 1) & 3;
    s.last = s.next;
    s.times[s.last] = time;
    s.lastDiffs[s.last] = 0;
    s.extremeCounters[s.last] = 0;
}

void GpsTimeEncoder::writeMultiple(ArithmeticEncoder& encoder, std::int32_t diff) {
    GpsTimeSequences<IntegerCompressor>& s = state_;
    const std::int32_t lastDiff = s.lastDiffs[s.last];
    const std::int32_t multiple = nearestMultiple(diff, lastDiff);
    if (multiple == 1) {
        encoder.encodeSymbol(s.multiModel, 1);
        s.integers.compress(encoder, lastDiff, diff, 1);
        s.extremeCounters[s.last] = 0;
    } else if (multiple > 1 && multiple < kGpsTimeMaxMultiple) {
        encoder.encodeSymbol(s.multiModel, static_cast<std::uint32_t>(multiple));
        s.integers.compress(encoder, wrappingMultiply(multiple, lastDiff), diff,
                            multiple < 10 ? 2 : 3);
    } else if (multiple >= kGpsTimeMaxMultiple) {
        encoder.encodeSymbol(s.multiModel, static_cast<std::uint32_t>(kGpsTimeMaxMultiple));
        s.integers.compress(encoder, wrappingMultiply(kGpsTimeMaxMultiple, lastDiff), diff, 4);
        s.countExtreme(diff);
    } else if (multiple < 0 && multiple > kGpsTimeMinMultiple) {
        encoder.encodeSymbol(s.multiModel,
                             static_cast<std::uint32_t>(kGpsTimeMaxMultiple - multiple));
        s.integers.compress(encoder, wrappingMultiply(multiple, lastDiff), diff, 5);
    } else if (multiple <= kGpsTimeMinMultiple) {
        encoder.encodeSymbol(s.multiModel,
                             static_cast<std::uint32_t>(kGpsTimeMaxMultiple - kGpsTimeMinMultiple));
        s.integers.compress(encoder, wrappingMultiply(kGpsTimeMinMultiple, lastDiff), diff, 6);
        s.countExtreme(diff);
    } else {  // 0: a difference far below the last one
        encoder.encodeSymbol(s.multiModel, 0);
        s.integers.compress(encoder, 0, diff, 7);
        s.countExtreme(diff);
    }
}

std::uint32_t encodeRgb(ArithmeticEncoder& encoder, RgbModels& models,
                        const std::array<std::uint16_t, 3>& last,
                        const std::array<std::uint16_t, 3>& now) {
    const auto low = [](std::uint16_t v) { return static_cast<std::int32_t>(v & 0xFF); };
    const auto high = [](std::uint16_t v) { return static_cast<std::int32_t>(v >> 8); };
    std::uint32_t changed = 0;
    for (std::uint32_t c = 0; c < 3; ++c) {
        changed |= (low(now[c]) != low(last[c]) ? 1u : 0u) << (2 * c);
        changed |= (high(now[c]) != high(last[c]) ? 1u : 0u) << (2 * c + 1);
    }
    const bool grey = now[1] == now[0] && now[2] == now[0];
    changed |= grey ? 0u : 1u << 6;
    encoder.encodeSymbol(models.changedBytes, changed);
    // Byte `bit` of the colour, where it changed: its difference to what the decoder predicts.
    const auto byteAt = [&](std::uint32_t bit, std::int32_t value, std::int32_t prediction) {
        if ((changed & (1u << bit)) != 0) {
            encoder.encodeSymbol(models.differences[bit], foldByte(value - prediction));
        }
    };
    byteAt(0, low(now[0]), low(last[0]));
    byteAt(1, high(now[0]), high(last[0]));
    if (grey) {
        return changed;  // green and blue are red's
    }
    std::int32_t diff = low(now[0]) - low(last[0]);
    byteAt(2, low(now[1]), clampByte(diff + low(last[1])));
    diff = (diff + low(now[1]) - low(last[1])) / 2;
    byteAt(4, low(now[2]), clampByte(diff + low(last[2])));
    diff = high(now[0]) - high(last[0]);
    byteAt(3, high(now[1]), clampByte(diff + high(last[1])));
    diff = (diff + high(now[1]) - high(last[1])) / 2;
    byteAt(5, high(now[2]), clampByte(diff + high(last[2])));
    return changed;
}

}  // namespace subscan::laz
