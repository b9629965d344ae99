#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "io/laz/ArithmeticDecoder.h"
#include "io/laz/IntegerDecompressor.h"

// Building blocks shared by the LASzip item decoders of both generations (pointwise "v2" and
// layered "v3"): the running median of coordinate differences, the GPS time and RGB predictors,
// and models created the first time a context value occurs.
namespace subscan::laz {

/// What C's U8_FOLD does to a sum of two bytes: wrap into 0..255.
inline std::uint8_t foldByte(std::int32_t value) {
    return static_cast<std::uint8_t>(value);
}

inline std::int32_t clampByte(std::int32_t value) {
    return value <= 0 ? 0 : (value >= 255 ? 255 : value);
}

/// int32 arithmetic that wraps like the encoder's instead of overflowing.
inline std::int32_t wrappingAdd(std::int32_t a, std::int32_t b) {
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) + static_cast<std::uint32_t>(b));
}
inline std::int32_t wrappingMultiply(std::int32_t a, std::int32_t b) {
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) * static_cast<std::uint32_t>(b));
}

/// The median of the last five values, kept sorted with the insertion rule of LASzip: a new
/// value replaces the oldest end of the window, alternating between the two ends.
class Median5 {
  public:
    void reset() {
        values_ = {};
        replaceHigh_ = true;
    }
    std::int32_t get() const { return values_[2]; }
    void add(std::int32_t v);

  private:
    std::array<std::int32_t, 5> values_{};
    bool replaceHigh_ = true;
};

/// A symbol model per context value (a previous byte, say), made when that value first occurs;
/// at a chunk start every model made so far goes back to its initial state.
class LazySymbolModels {
  public:
    LazySymbolModels(std::size_t contexts, std::uint32_t symbols)
        : models_(contexts), symbols_(symbols) {}

    SymbolModel& operator[](std::size_t context) {
        std::unique_ptr<SymbolModel>& model = models_[context];
        if (!model) {
            model = std::make_unique<SymbolModel>(symbols_);
        }
        return *model;
    }
    void reset() {
        for (std::unique_ptr<SymbolModel>& model : models_) {
            if (model) {
                model->reset();
            }
        }
    }

  private:
    std::vector<std::unique_ptr<SymbolModel>> models_;
    std::uint32_t symbols_;
};

// GPS time as LASzip predicts it: up to four interleaved sequences (flight lines, returns), each
// with its last time and its last difference in the time's integer (bit-pattern) units. A new
// time is a multiple of the last difference plus a corrector, a switch to another sequence, or
// a full new time. The two generations number their codes differently (`pointwise`: GPSTIME11
// v2, which also codes "unchanged"; otherwise POINT14 v3, which is asked only on a change).

/// Multiples of the last difference run from -10 to 500.
inline constexpr std::int32_t kGpsTimeMaxMultiple = 500;
inline constexpr std::int32_t kGpsTimeMinMultiple = -10;
/// Symbol of "a full new time" in the multiple model; the symbols after it switch sequences.
inline constexpr std::uint32_t kGpsTimeFullCode =
    kGpsTimeMaxMultiple - kGpsTimeMinMultiple + 1;  // 511

/// The state both sides of the GPS time coder keep; `IntegerCoder` is the IntegerCompressor or
/// the IntegerDecompressor.
template <class IntegerCoder>
struct GpsTimeSequences {
    explicit GpsTimeSequences(bool pointwise)
        : multiModel(pointwise ? 516 : 515), zeroDiffModel(pointwise ? 6 : 5) {}

    void reset(std::uint64_t firstTimeBits) {
        multiModel.reset();
        zeroDiffModel.reset();
        integers.reset();
        last = 0;
        next = 0;
        times = {static_cast<std::int64_t>(firstTimeBits), 0, 0, 0};
        lastDiffs = {};
        extremeCounters = {};
    }

    /// An extreme multiple (0, the largest or the most negative) four times in a row makes
    /// `diff` the sequence's new difference.
    void countExtreme(std::int32_t diff) {
        if (++extremeCounters[last] > 3) {
            lastDiffs[last] = diff;
            extremeCounters[last] = 0;
        }
    }

    SymbolModel multiModel;
    SymbolModel zeroDiffModel;
    IntegerCoder integers{32, 9};
    std::uint32_t last = 0;  // the sequence of the last time
    std::uint32_t next = 0;  // the sequence a full new time starts
    std::array<std::int64_t, 4> times{};
    std::array<std::int32_t, 4> lastDiffs{};
    std::array<std::int32_t, 4> extremeCounters{};
};

class GpsTimeDecoder {
  public:
    /// The default is POINT14's coder, so that it default-constructs like the GpsTimeEncoder.
    explicit GpsTimeDecoder(bool pointwise = false) : pointwise_(pointwise), state_(pointwise) {}
    void reset(std::uint64_t firstTimeBits) { state_.reset(firstTimeBits); }
    void decode(ArithmeticDecoder& decoder);
    std::uint64_t timeBits() const { return static_cast<std::uint64_t>(state_.times[state_.last]); }

  private:
    void readFullTime(ArithmeticDecoder& decoder);

    bool pointwise_;
    GpsTimeSequences<IntegerDecompressor> state_;
};

/// The RGB predictor of RGB12 v2 and RGB14 v3: a mask of which bytes changed, the low and high
/// bytes of red coded as differences, green and blue predicted from red's change.
struct RgbModels {
    SymbolModel changedBytes{128};
    std::array<SymbolModel, 6> differences{SymbolModel(256), SymbolModel(256), SymbolModel(256),
                                           SymbolModel(256), SymbolModel(256), SymbolModel(256)};
    void reset();
};

/// Decodes one colour given the last one; both are R, G, B as stored (16-bit).
std::array<std::uint16_t, 3> decodeRgb(ArithmeticDecoder& decoder, RgbModels& models,
                                       const std::array<std::uint16_t, 3>& last);

}  // namespace subscan::laz
