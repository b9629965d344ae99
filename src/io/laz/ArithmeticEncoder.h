#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "io/laz/ArithmeticModels.h"

// The entropy encoder of LASzip, the mirror of ArithmeticDecoder (Isenburg 2013; Said &
// Pearlman's FastAC with 32-bit state): the interval [base, base + length) narrows by each coded
// decision; whenever its length drops below 2^24 its top byte is settled and written. A sum
// that overflows 32 bits carries into the bytes already written. The models are the decoder's
// (ArithmeticModels.h), updated on the same schedule.
namespace subscan::laz {

class ArithmeticEncoder {
  public:
    void encodeBit(BitModel& model, std::uint32_t bit) {
        const std::uint32_t split = model.bit0Probability * (length_ >> kBitLengthShift);
        if (bit == 0) {
            length_ = split;
            ++model.bit0Count;
        } else {
            add(split);
            length_ -= split;
        }
        if (length_ < kMinLength) {
            renormalise();
        }
        if (--model.bitsUntilUpdate == 0) {
            model.update();
        }
    }

    /// `symbol` must lie in [0, model.symbols).
    void encodeSymbol(SymbolModel& model, std::uint32_t symbol) {
        if (symbol == model.lastSymbol) {
            // The last symbol takes the rest of the interval, as the decoder's upper bound does.
            const std::uint32_t lower =
                model.distribution[symbol] * (length_ >> kSymbolLengthShift);
            add(lower);
            length_ -= lower;
        } else {
            length_ >>= kSymbolLengthShift;
            const std::uint32_t lower = model.distribution[symbol] * length_;
            add(lower);
            length_ = model.distribution[symbol + 1] * length_ - lower;
        }
        if (length_ < kMinLength) {
            renormalise();
        }
        ++model.counts[symbol];
        if (--model.symbolsUntilUpdate == 0) {
            model.update();
        }
    }

    /// The low `bits` (1..32) bits of `value`, raw; more than 19 go as the low 16 bits first,
    /// then the rest (what ArithmeticDecoder::readBits reads).
    void writeBits(std::uint32_t bits, std::uint32_t value) {
        if (bits > 19) {
            writeBits(16, value & 0xFFFFu);
            writeBits(bits - 16, value >> 16);
            return;
        }
        length_ >>= bits;
        add(value * length_);
        if (length_ < kMinLength) {
            renormalise();
        }
    }

    void writeShort(std::uint32_t value) { writeBits(16, value & 0xFFFFu); }
    void writeInt(std::uint32_t value) {
        writeShort(value);
        writeShort(value >> 16);
    }

    /// Ends the stream and returns its bytes; the encoder starts a new stream afterwards.
    std::vector<std::byte> finish();

  private:
    void add(std::uint32_t value) {
        const std::uint32_t before = base_;
        base_ += value;
        if (base_ < before) {
            propagateCarry();
        }
    }
    void propagateCarry();
    /// Writes the settled top bytes until the interval is at least 2^24 long again.
    void renormalise() {
        do {
            bytes_.push_back(static_cast<std::byte>(base_ >> 24));
            base_ <<= 8;
            length_ <<= 8;
        } while (length_ < kMinLength);
    }

    std::vector<std::byte> bytes_;
    std::uint32_t base_ = 0;
    std::uint32_t length_ = kMaxLength;
};

}  // namespace subscan::laz
