#include "io/laz/ArithmeticModels.h"

#include <algorithm>

namespace subscan::laz {

void BitModel::update() {
    bitCount += updateCycle;
    if (bitCount > kBitMaxCount) {
        bitCount = (bitCount + 1) >> 1;
        bit0Count = (bit0Count + 1) >> 1;
        if (bit0Count == bitCount) {
            ++bitCount;
        }
    }
    const std::uint32_t scale = 0x80000000u / bitCount;
    bit0Probability = (bit0Count * scale) >> (31 - kBitLengthShift);
    updateCycle = std::min<std::uint32_t>((5 * updateCycle) >> 2, 64);
    bitsUntilUpdate = updateCycle;
}

SymbolModel::SymbolModel(std::uint32_t symbolCount)
    : symbols(symbolCount),
      lastSymbol(symbolCount - 1),
      distribution(symbolCount),
      counts(symbolCount) {
    if (symbols > 16) {
        std::uint32_t tableBits = 3;
        while (symbols > (1u << (tableBits + 2))) {
            ++tableBits;
        }
        tableShift = kSymbolLengthShift - tableBits;
        decoderTable.resize((1u << tableBits) + 2);
    }
    reset();
}

void SymbolModel::reset() {
    std::fill(counts.begin(), counts.end(), 1u);
    totalCount = 0;
    updateCycle = symbols;
    update();
    updateCycle = (symbols + 6) >> 1;
    symbolsUntilUpdate = updateCycle;
}

void SymbolModel::update() {
    totalCount += updateCycle;
    if (totalCount > kSymbolMaxCount) {
        totalCount = 0;
        for (std::uint32_t& count : counts) {
            count = (count + 1) >> 1;
            totalCount += count;
        }
    }
    const std::uint32_t scale = 0x80000000u / totalCount;
    std::uint32_t sum = 0;
    if (decoderTable.empty()) {
        for (std::uint32_t k = 0; k < symbols; ++k) {
            distribution[k] = (scale * sum) >> (31 - kSymbolLengthShift);
            sum += counts[k];
        }
    } else {
        const auto tableSize = static_cast<std::uint32_t>(decoderTable.size() - 2);
        std::uint32_t slot = 0;
        for (std::uint32_t k = 0; k < symbols; ++k) {
            distribution[k] = (scale * sum) >> (31 - kSymbolLengthShift);
            sum += counts[k];
            const std::uint32_t reached = distribution[k] >> tableShift;
            while (slot < reached) {
                decoderTable[++slot] = k - 1;
            }
        }
        decoderTable[0] = 0;
        while (slot <= tableSize) {
            decoderTable[++slot] = symbols - 1;
        }
    }
    updateCycle = std::min((5 * updateCycle) >> 2, (symbols + 6) << 3);
    symbolsUntilUpdate = updateCycle;
}

}  // namespace subscan::laz
