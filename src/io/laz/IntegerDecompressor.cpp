#include "io/laz/IntegerDecompressor.h"

namespace subscan::laz {

std::int32_t IntegerDecompressor::readCorrector(ArithmeticDecoder& decoder, SymbolModel& kModel) {
    k_ = decoder.decodeSymbol(kModel);
    if (k_ == 0) {
        return static_cast<std::int32_t>(decoder.decodeBit(models_.correctorZero));
    }
    if (k_ >= 32) {
        return models_.correctorMin;
    }
    std::uint32_t c = decoder.decodeSymbol(models_.correctorModels[k_ - 1]);
    if (k_ > IntegerModels::kBitsHigh) {
        const std::uint32_t lowBits = k_ - IntegerModels::kBitsHigh;
        c = (c << lowBits) | decoder.readBits(lowBits);
    }
    // c in [0, 2^k): the upper half maps to positive correctors, the lower to negative ones.
    if (c >= (1u << (k_ - 1))) {
        return static_cast<std::int32_t>(c + 1);
    }
    return static_cast<std::int32_t>(c) - static_cast<std::int32_t>((1u << k_) - 1);
}

}  // namespace subscan::laz
