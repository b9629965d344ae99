#pragma once

#include <cstdint>
#include <vector>

#include "io/laz/ArithmeticDecoder.h"

namespace subscan::laz {

/// LASzip's predictive integer coder: a value is its prediction plus a corrector. The corrector
/// is coded as k, the number of its significant bits (one adaptive symbol per context), then, for
/// k > 0, the corrector's position within [-(2^k - 1), -2^(k-1)] or [2^(k-1) + 1, 2^k]: its top
/// min(k, 8) bits as an adaptive symbol of model k, the rest raw; k = 0 is 0 or 1 (a bit model).
/// Values live in a range of 2^bits (32: all of int32), so sums wrap around that range.
class IntegerDecompressor {
  public:
    explicit IntegerDecompressor(std::uint32_t bits = 16, std::uint32_t contexts = 1);

    /// Back to the initial state, as at the start of a chunk.
    void reset();

    std::int32_t decompress(ArithmeticDecoder& decoder, std::int32_t prediction,
                            std::uint32_t context = 0) {
        // Unsigned arithmetic: the sum wraps like the encoder's instead of overflowing.
        auto real = static_cast<std::uint32_t>(prediction) +
                    static_cast<std::uint32_t>(readCorrector(decoder, kModels_[context]));
        if (correctorRange_ != 0) {
            if (static_cast<std::int32_t>(real) < 0) {
                real += correctorRange_;
            } else if (real >= correctorRange_) {
                real -= correctorRange_;
            }
        }
        return static_cast<std::int32_t>(real);
    }

    /// k of the last decompressed value; item coders use it to pick the next context.
    std::uint32_t lastK() const { return k_; }

  private:
    static constexpr std::uint32_t kBitsHigh = 8;

    std::int32_t readCorrector(ArithmeticDecoder& decoder, SymbolModel& kModel);

    std::uint32_t correctorBits_;
    std::uint32_t correctorRange_;  // 0 for 32-bit values: the wrap of uint32 is the range
    std::int32_t correctorMin_;
    std::uint32_t k_ = 0;
    std::vector<SymbolModel> kModels_;
    BitModel correctorZero_;
    std::vector<SymbolModel> correctorModels_;  // index k - 1
};

}  // namespace subscan::laz
