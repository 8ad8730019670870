// CRC-32, Adler-32 and a fixed-Huffman deflate compressor (RFC 1951 §3.2.6) for the PNG writer;
// see deflate.hpp. Greedy LZ77 with hash chains, as zlib's fast levels do, but with the fixed
// code tables only: a small, dependency-free encoder that still makes rendered meshes 10-20x
// smaller than stored blocks.
#include "render/deflate.hpp"

#include <algorithm>
#include <array>
#include <cstddef>

namespace g2s::render {
namespace {

constexpr std::size_t kWindow = 32768;
constexpr std::size_t kMinMatch = 3;
constexpr std::size_t kMaxMatch = 258;
constexpr int kMaxChain = 64;  // candidates tried per position: speed against ratio
constexpr int kHashBits = 15;

constexpr std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t n = 0; n < 256; ++n) {
    std::uint32_t c = n;
    for (int k = 0; k < 8; ++k) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[n] = c;
  }
  return table;
}
constexpr std::array<std::uint32_t, 256> kCrcTable = make_crc_table();

// Length symbols 257..285: base length and extra bits (RFC 1951 §3.2.5).
constexpr std::array<std::uint16_t, 29> kLengthBase{3,  4,  5,  6,   7,   8,   9,   10,  11, 13,
                                                    15, 17, 19, 23,  27,  31,  35,  43,  51, 59,
                                                    67, 83, 99, 115, 131, 163, 195, 227, 258};
constexpr std::array<std::uint8_t, 29> kLengthExtra{0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                                    2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
// Distance symbols 0..29.
constexpr std::array<std::uint16_t, 30> kDistBase{
    1,   2,   3,   4,   5,   7,    9,    13,   17,   25,   33,   49,   65,    97,    129,
    193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
constexpr std::array<std::uint8_t, 30> kDistExtra{0, 0, 0,  0,  1,  1,  2,  2,  3,  3,
                                                  4, 4, 5,  5,  6,  6,  7,  7,  8,  8,
                                                  9, 9, 10, 10, 11, 11, 12, 12, 13, 13};

// Packs bits least significant first, as deflate stores everything but Huffman codes.
class BitWriter {
 public:
  explicit BitWriter(std::vector<std::uint8_t>& out) : out_(out) {}
  void bits(std::uint32_t value, int count) {
    acc_ |= static_cast<std::uint64_t>(value) << used_;
    used_ += count;
    while (used_ >= 8) {
      out_.push_back(static_cast<std::uint8_t>(acc_));
      acc_ >>= 8;
      used_ -= 8;
    }
  }
  // A Huffman code goes most significant bit first: reverse it into the LSB-first stream.
  void code(std::uint32_t code, int length) {
    std::uint32_t reversed = 0;
    for (int i = 0; i < length; ++i) reversed |= ((code >> i) & 1u) << (length - 1 - i);
    bits(reversed, length);
  }
  void flush() {
    if (used_ > 0) out_.push_back(static_cast<std::uint8_t>(acc_));
    acc_ = 0;
    used_ = 0;
  }

 private:
  std::vector<std::uint8_t>& out_;
  std::uint64_t acc_ = 0;
  int used_ = 0;
};

// The fixed literal/length code of symbol 0..287 (RFC 1951 §3.2.6).
void put_symbol(BitWriter& w, std::uint32_t symbol) {
  if (symbol < 144) {
    w.code(0x30 + symbol, 8);
  } else if (symbol < 256) {
    w.code(0x190 + symbol - 144, 9);
  } else if (symbol < 280) {
    w.code(symbol - 256, 7);
  } else {
    w.code(0xC0 + symbol - 280, 8);
  }
}

void put_match(BitWriter& w, std::size_t length, std::size_t distance) {
  const auto l = static_cast<std::size_t>(
      std::upper_bound(kLengthBase.begin(), kLengthBase.end(), length) - kLengthBase.begin() - 1);
  put_symbol(w, static_cast<std::uint32_t>(257 + l));
  w.bits(static_cast<std::uint32_t>(length - kLengthBase[l]), kLengthExtra[l]);
  const auto d = static_cast<std::size_t>(
      std::upper_bound(kDistBase.begin(), kDistBase.end(), distance) - kDistBase.begin() - 1);
  w.code(static_cast<std::uint32_t>(d), 5);
  w.bits(static_cast<std::uint32_t>(distance - kDistBase[d]), kDistExtra[d]);
}

std::uint32_t hash3(const std::uint8_t* p) {
  const std::uint32_t v =
      static_cast<std::uint32_t>(p[0]) << 16 | static_cast<std::uint32_t>(p[1]) << 8 | p[2];
  return (v * 2654435761u) >> (32 - kHashBits);
}

}  // namespace

std::uint32_t crc32(std::span<const std::uint8_t> data, std::uint32_t crc) {
  crc = ~crc;
  for (const std::uint8_t byte : data) crc = kCrcTable[(crc ^ byte) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

std::uint32_t adler32(std::span<const std::uint8_t> data) {
  constexpr std::uint32_t kMod = 65521;
  std::uint32_t a = 1, b = 0;
  // 5552 bytes is the longest run whose sums cannot overflow 32 bits before the modulo.
  for (std::size_t begin = 0; begin < data.size(); begin += 5552) {
    const std::size_t end = std::min(data.size(), begin + 5552);
    for (std::size_t i = begin; i < end; ++i) {
      a += data[i];
      b += a;
    }
    a %= kMod;
    b %= kMod;
  }
  return b << 16 | a;
}

std::vector<std::uint8_t> zlib_compress(std::span<const std::uint8_t> data) {
  std::vector<std::uint8_t> out{0x78, 0x01};  // deflate, 32 KiB window, no dictionary
  BitWriter w(out);
  w.bits(1, 1);  // BFINAL: the only block
  w.bits(1, 2);  // BTYPE 01: fixed Huffman codes
  // head[h]: the latest position whose next 3 bytes hash to h; prev[i % window]: the one before.
  constexpr std::uint32_t kNone = 0xFFFFFFFFu;
  std::vector<std::uint32_t> head(std::size_t{1} << kHashBits, kNone);
  std::vector<std::uint32_t> prev(kWindow, kNone);
  const std::size_t n = data.size();
  auto insert = [&](std::size_t i) {
    if (i + kMinMatch > n) return;
    const std::uint32_t h = hash3(&data[i]);
    prev[i % kWindow] = head[h];
    head[h] = static_cast<std::uint32_t>(i);
  };
  std::size_t i = 0;
  while (i < n) {
    std::size_t best_length = 0, best_distance = 0;
    if (i + kMinMatch <= n) {
      const std::size_t limit = std::min(kMaxMatch, n - i);
      std::uint32_t candidate = head[hash3(&data[i])];
      for (int chain = 0; chain < kMaxChain && candidate != kNone; ++chain) {
        if (i - candidate > kWindow - 1) break;  // older ones are further still
        std::size_t length = 0;
        while (length < limit && data[candidate + length] == data[i + length]) ++length;
        if (length > best_length) {
          best_length = length;
          best_distance = i - candidate;
          if (length == limit) break;
        }
        const std::uint32_t next = prev[candidate % kWindow];
        if (next == kNone || next >= candidate) break;  // the slot was reused by a newer one
        candidate = next;
      }
    }
    if (best_length >= kMinMatch) {
      put_match(w, best_length, best_distance);
      for (std::size_t k = 0; k < best_length; ++k) insert(i + k);
      i += best_length;
    } else {
      put_symbol(w, data[i]);
      insert(i);
      ++i;
    }
  }
  put_symbol(w, 256);  // end of block
  w.flush();
  const std::uint32_t adler = adler32(data);
  for (int shift = 24; shift >= 0; shift -= 8)
    out.push_back(static_cast<std::uint8_t>(adler >> shift));
  return out;
}

}  // namespace g2s::render
