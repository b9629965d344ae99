#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace subscan {

template <class T>
T byteSwapped(T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    if constexpr (sizeof(T) == 1) {
        return value;
    } else if constexpr (sizeof(T) == 2) {
        return std::bit_cast<T>(__builtin_bswap16(std::bit_cast<std::uint16_t>(value)));
    } else if constexpr (sizeof(T) == 4) {
        return std::bit_cast<T>(__builtin_bswap32(std::bit_cast<std::uint32_t>(value)));
    } else {
        static_assert(sizeof(T) == 8);
        return std::bit_cast<T>(__builtin_bswap64(std::bit_cast<std::uint64_t>(value)));
    }
}

/// Reads a T stored little-endian at `p` (no alignment needed).
template <class T>
T loadLittleEndian(const void* p) {
    T value;
    std::memcpy(&value, p, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) {
        value = byteSwapped(value);
    }
    return value;
}

/// Stores `value` little-endian at `p` (no alignment needed).
template <class T>
void storeLittleEndian(void* p, T value) {
    if constexpr (std::endian::native == std::endian::big) {
        value = byteSwapped(value);
    }
    std::memcpy(p, &value, sizeof(T));
}

/// Reads a T stored big-endian at `p` (no alignment needed).
template <class T>
T loadBigEndian(const void* p) {
    T value;
    std::memcpy(&value, p, sizeof(T));
    if constexpr (std::endian::native == std::endian::little) {
        value = byteSwapped(value);
    }
    return value;
}

}  // namespace subscan
