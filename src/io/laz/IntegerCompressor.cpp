#include "io/laz/IntegerCompressor.h"

#include <bit>

namespace subscan::laz {

void IntegerCompressor::writeCorrector(ArithmeticEncoder& encoder, std::int32_t corrector,
                                       SymbolModel& kModel) {
    // k: the smallest with the corrector in [-(2^k - 1), 2^k]. Magnitudes in unsigned
    // arithmetic, so that the range's minimum (-2^31, k = 32) is no overflow.
    const auto c = static_cast<std::uint32_t>(corrector);
    const std::uint32_t magnitude = corrector <= 0 ? 0u - c : c - 1;
    k_ = static_cast<std::uint32_t>(std::bit_width(magnitude));
    encoder.encodeSymbol(kModel, k_);
    if (k_ == 0) {
        encoder.encodeBit(models_.correctorZero, c);  // the corrector is 0 or 1
        return;
    }
    if (k_ >= 32) {
        return;  // only the range's minimum has 32 bits: the decoder knows it from k alone
    }
    // The corrector's position in its k-bit interval: [-(2^k - 1), -2^(k-1)] maps to the lower
    // half of [0, 2^k), [2^(k-1) + 1, 2^k] to the upper half.
    const std::uint32_t position = corrector < 0 ? c + ((1u << k_) - 1) : c - 1;
    if (k_ <= IntegerModels::kBitsHigh) {
        encoder.encodeSymbol(models_.correctorModels[k_ - 1], position);
        return;
    }
    const std::uint32_t lowBits = k_ - IntegerModels::kBitsHigh;
    encoder.encodeSymbol(models_.correctorModels[k_ - 1], position >> lowBits);
    encoder.writeBits(lowBits, position & ((1u << lowBits) - 1));
}

}  // namespace subscan::laz
