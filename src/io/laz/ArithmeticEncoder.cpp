#include "io/laz/ArithmeticEncoder.h"

#include <utility>

namespace subscan::laz {

void ArithmeticEncoder::propagateCarry() {
    // The carry turns a run of trailing 0xFF bytes into zeros and increments the byte before it.
    // The interval never lies above 2^32 before the first byte is written, so there is one.
    std::size_t i = bytes_.size();
    while (i > 0 && bytes_[i - 1] == std::byte{0xFF}) {
        bytes_[--i] = std::byte{0};
    }
    if (i > 0) {
        bytes_[i - 1] = static_cast<std::byte>(static_cast<unsigned>(bytes_[i - 1]) + 1);
    }
}

std::vector<std::byte> ArithmeticEncoder::finish() {
    // Pick a value inside the final interval that the fewest further bytes pin down: one byte
    // where the interval is longer than 2^25, else two.
    bool oneByte = true;
    if (length_ > 2 * kMinLength) {
        add(kMinLength);
        length_ = kMinLength >> 1;
    } else {
        add(kMinLength >> 1);
        length_ = kMinLength >> 9;
        oneByte = false;
    }
    renormalise();
    // The decoder reads four bytes ahead of what it decodes: zeros keep those reads inside the
    // stream (two or three, so that the stream's tail is always four bytes).
    bytes_.resize(bytes_.size() + (oneByte ? 3 : 2), std::byte{0});

    std::vector<std::byte> bytes = std::move(bytes_);
    bytes_.clear();
    base_ = 0;
    length_ = kMaxLength;
    return bytes;
}

}  // namespace subscan::laz
