#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "core/Error.h"
#include "io/laz/ArithmeticModels.h"

// The entropy decoder of LASzip (Isenburg 2013, "LASzip: lossless compression of LiDAR data"),
// an adaptive range coder after Said & Pearlman's FastAC with 32-bit state, written from that
// description. Every LAZ item decoder is built on three primitives: adaptive bits, adaptive
// symbols of an alphabet of up to 2048 (the models of ArithmeticModels.h), and raw bits.
namespace subscan::laz {

/// Reads the coded bytes of one stream. Valid streams end with padding that keeps the decoder's
/// reads inside them, so a read past the end means the stream was cut short or is corrupt.
class ArithmeticDecoder {
  public:
    ArithmeticDecoder() = default;
    explicit ArithmeticDecoder(std::span<const std::byte> bytes) { start(bytes); }

    /// Starts decoding `bytes`: the first four bytes fill the value register.
    void start(std::span<const std::byte> bytes) {
        next_ = bytes.data();
        end_ = bytes.data() + bytes.size();
        length_ = kMaxLength;
        value_ = 0;
        for (int i = 0; i < 4; ++i) {
            value_ = (value_ << 8) | nextByte();
        }
    }

    std::uint32_t decodeBit(BitModel& model) {
        const std::uint32_t split = model.bit0Probability * (length_ >> kBitLengthShift);
        std::uint32_t bit;
        if (value_ < split) {
            bit = 0;
            length_ = split;
            ++model.bit0Count;
        } else {
            bit = 1;
            value_ -= split;
            length_ -= split;
        }
        if (length_ < kMinLength) {
            renormalise();
        }
        if (--model.bitsUntilUpdate == 0) {
            model.update();
        }
        return bit;
    }

    std::uint32_t decodeSymbol(SymbolModel& model) {
        // A valid stream keeps the value inside the interval; a corrupt one could index past
        // the decoder table.
        if (value_ >= length_) {
            throw Error("the LAZ point data is corrupt (a coded value lies outside its interval)");
        }
        std::uint32_t upper = length_;
        std::uint32_t symbol;
        std::uint32_t lower;
        length_ >>= kSymbolLengthShift;
        if (!model.decoderTable.empty()) {
            // The table narrows [symbol, end) to a few candidates; bisection finishes.
            const std::uint32_t scaled = value_ / length_;
            const std::uint32_t slot = scaled >> model.tableShift;
            symbol = model.decoderTable[slot];
            std::uint32_t end = model.decoderTable[slot + 1] + 1;
            while (end > symbol + 1) {
                const std::uint32_t middle = (symbol + end) >> 1;
                if (model.distribution[middle] > scaled) {
                    end = middle;
                } else {
                    symbol = middle;
                }
            }
            lower = model.distribution[symbol] * length_;
            if (symbol != model.lastSymbol) {
                upper = model.distribution[symbol + 1] * length_;
            }
        } else {
            // Bisection on the products: the largest symbol whose lower bound is <= value.
            symbol = 0;
            lower = 0;
            std::uint32_t end = model.symbols;
            std::uint32_t middle = end >> 1;
            do {
                const std::uint32_t bound = length_ * model.distribution[middle];
                if (bound > value_) {
                    end = middle;
                    upper = bound;
                } else {
                    symbol = middle;
                    lower = bound;
                }
                middle = (symbol + end) >> 1;
            } while (middle != symbol);
        }
        value_ -= lower;
        length_ = upper - lower;
        if (length_ < kMinLength) {
            renormalise();
        }
        ++model.counts[symbol];
        if (--model.symbolsUntilUpdate == 0) {
            model.update();
        }
        return symbol;
    }

    /// `bits` (1..32) raw bits, low 16 first when more than 19 are asked for.
    std::uint32_t readBits(std::uint32_t bits) {
        if (bits > 19) {
            const std::uint32_t low = readShort();
            return (readBits(bits - 16) << 16) | low;
        }
        length_ >>= bits;
        const std::uint32_t symbol = value_ / length_;
        value_ -= length_ * symbol;
        if (length_ < kMinLength) {
            renormalise();
        }
        if (symbol >> bits) {
            throw Error("the LAZ point data is corrupt (a raw value exceeds its bit width)");
        }
        return symbol;
    }

    std::uint32_t readShort() { return readBits(16); }
    std::uint32_t readInt() {
        const std::uint32_t low = readShort();
        return (readShort() << 16) | low;
    }

  private:
    std::uint32_t nextByte() {
        if (next_ == end_) {
            throw Error(
                "the LAZ point data ends inside a compressed stream (file truncated, or a "
                "chunk is corrupt)");
        }
        return static_cast<std::uint32_t>(*next_++);
    }

    void renormalise() {
        do {
            value_ = (value_ << 8) | nextByte();
            length_ <<= 8;
        } while (length_ < kMinLength);
    }

    const std::byte* next_ = nullptr;
    const std::byte* end_ = nullptr;
    std::uint32_t value_ = 0;
    std::uint32_t length_ = kMaxLength;
};

}  // namespace subscan::laz
