// Little-endian encoding of numbers into byte buffers for the binary writers (STL, PLY), and
// decoding for the LAS reader, correct on any host byte order.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>

namespace g2s::io {

// `value` with its bytes in little-endian order (swapped on a big-endian host; its own inverse).
template <typename T>
inline T little_endian_order(T value) {
  static_assert(sizeof(T) == 1 || sizeof(T) == 2 || sizeof(T) == 4 || sizeof(T) == 8);
  if constexpr (std::endian::native == std::endian::big && sizeof(T) > 1) {
    if constexpr (sizeof(T) == 2) {
      value = std::bit_cast<T>(__builtin_bswap16(std::bit_cast<std::uint16_t>(value)));
    } else if constexpr (sizeof(T) == 4) {
      value = std::bit_cast<T>(__builtin_bswap32(std::bit_cast<std::uint32_t>(value)));
    } else {
      value = std::bit_cast<T>(__builtin_bswap64(std::bit_cast<std::uint64_t>(value)));
    }
  }
  return value;
}

template <typename T>
inline char* put_le(char* dst, T value) {
  value = little_endian_order(value);
  std::memcpy(dst, &value, sizeof(T));
  return dst + sizeof(T);
}

// The little-endian T at src (unaligned is fine).
template <typename T>
inline T get_le(const unsigned char* src) {
  T value;
  std::memcpy(&value, src, sizeof(T));
  return little_endian_order(value);
}

}  // namespace g2s::io
