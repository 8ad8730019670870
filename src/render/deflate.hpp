// The checksums and the compressor behind the PNG writer (png_writer.cpp): CRC-32 (PNG chunks),
// Adler-32 and a zlib stream (RFC 1950/1951) made of one deflate block with the fixed Huffman
// codes. Fixed codes need no code-length tables, and on rendered pictures (large even
// backgrounds, repeated rows) LZ77 does nearly all of the work.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace g2s::render {

// CRC-32 (ISO-HDLC, reflected polynomial 0xEDB88320) of data, continuing from crc (0 to start).
std::uint32_t crc32(std::span<const std::uint8_t> data, std::uint32_t crc = 0);

// Adler-32 of data (RFC 1950 §8).
std::uint32_t adler32(std::span<const std::uint8_t> data);

// data as a zlib stream: header 78 01, one final fixed-Huffman block (greedy LZ77 over a 32 KiB
// window, matches of 3..258 bytes found through hash chains of bounded length), Adler-32.
std::vector<std::uint8_t> zlib_compress(std::span<const std::uint8_t> data);

}  // namespace g2s::render
