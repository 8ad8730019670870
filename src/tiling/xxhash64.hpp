// XXH64 (Yann Collet's xxHash, 64-bit variant, seed 0), the checksum of the tile store's header,
// table and frames: fast enough that verifying a frame costs little next to reading it. zstd
// carries a copy but does not export it, so this is a small independent implementation of the
// published algorithm (its frame checksums, the low 32 bits of XXH64, check it in the tests).
#pragma once

#include <cstddef>
#include <cstdint>

namespace g2s::tiling {

std::uint64_t xxhash64(const void* data, std::size_t bytes);

}  // namespace g2s::tiling
