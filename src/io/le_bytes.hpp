// Little-endian encoding of numbers into byte buffers for the binary writers (STL, PLY), correct
// on any host byte order.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>

namespace g2s::io {

template <typename T>
inline char* put_le(char* dst, T value) {
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
  std::memcpy(dst, &value, sizeof(T));
  return dst + sizeof(T);
}

}  // namespace g2s::io
