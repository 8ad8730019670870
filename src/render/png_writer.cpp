// PNG encoding of rendered pictures (include/g2s/render.hpp: encode_png, write_png), following
// the PNG specification (ISO/IEC 15948): signature, IHDR, PLTE when there is a palette, one IDAT,
// IEND, each chunk with its CRC-32. Rendered meshes have few colours (quantised shading), so they
// are written as palette images: a third of the bytes to compress. Other images are RGB, each row
// filtered with the minimum-sum-of-magnitudes heuristic the specification recommends (§12.8).
// Both are deflated by render/deflate.cpp.
#include <fmt/core.h>

#include <array>
#include <cstdlib>
#include <string_view>
#include <unordered_map>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/render.hpp"
#include "render/deflate.hpp"

namespace g2s {
namespace {

constexpr std::array<std::uint8_t, 8> kSignature{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};

void put_be32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(v >> shift));
}

void put_chunk(std::vector<std::uint8_t>& out, std::string_view type,
               std::span<const std::uint8_t> data) {
  put_be32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = out.size();
  out.insert(out.end(), type.begin(), type.end());
  out.insert(out.end(), data.begin(), data.end());
  put_be32(out, render::crc32(std::span(out).subspan(start)));
}

std::uint8_t paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return static_cast<std::uint8_t>(a);
  return static_cast<std::uint8_t>(pb <= pc ? b : c);
}

// The filtered scanlines, each a filter type byte then the row: the filter (0 none, 1 sub, 2 up,
// 4 Paeth) whose bytes, read as signed, have the smallest sum of magnitudes.
std::vector<std::uint8_t> filter_rows(const Image& image) {
  const std::size_t stride = 3 * static_cast<std::size_t>(image.width);
  std::vector<std::uint8_t> out;
  out.reserve((stride + 1) * static_cast<std::size_t>(image.height));
  const std::vector<std::uint8_t> zero_row(stride, 0);
  std::array<std::vector<std::uint8_t>, 4> trial;
  constexpr std::array<std::uint8_t, 4> kTypes{0, 1, 2, 4};
  for (int y = 0; y < image.height; ++y) {
    const std::uint8_t* row = &image.rgb[static_cast<std::size_t>(y) * stride];
    const std::uint8_t* up = y > 0 ? row - stride : zero_row.data();
    std::size_t best = 0;
    std::uint64_t best_cost = ~0ull;
    for (std::size_t f = 0; f < kTypes.size(); ++f) {
      trial[f].resize(stride);
      std::uint64_t cost = 0;
      for (std::size_t x = 0; x < stride; ++x) {
        const int a = x >= 3 ? row[x - 3] : 0, b = up[x], c = x >= 3 ? up[x - 3] : 0;
        int predictor = 0;
        switch (kTypes[f]) {
          case 1:
            predictor = a;
            break;
          case 2:
            predictor = b;
            break;
          case 4:
            predictor = paeth(a, b, c);
            break;
          default:
            break;
        }
        const auto v = static_cast<std::uint8_t>(row[x] - predictor);
        trial[f][x] = v;
        cost += static_cast<std::uint64_t>(std::abs(static_cast<int>(static_cast<std::int8_t>(v))));
      }
      if (cost < best_cost) {
        best_cost = cost;
        best = f;
      }
    }
    out.push_back(kTypes[best]);
    out.insert(out.end(), trial[best].begin(), trial[best].end());
  }
  return out;
}

// The image as palette indices, when it has at most 256 colours: the palette (3 bytes a
// colour, in order of first appearance) and one index byte per pixel. False when it has more.
bool to_palette(const Image& image, std::vector<std::uint8_t>& palette,
                std::vector<std::uint8_t>& indices) {
  std::unordered_map<std::uint32_t, std::uint8_t> index_of;
  indices.resize(image.rgb.size() / 3);
  for (std::size_t i = 0; i < indices.size(); ++i) {
    const std::uint32_t colour = static_cast<std::uint32_t>(image.rgb[3 * i]) << 16 |
                                 static_cast<std::uint32_t>(image.rgb[3 * i + 1]) << 8 |
                                 image.rgb[3 * i + 2];
    auto [it, added] = index_of.try_emplace(colour, static_cast<std::uint8_t>(index_of.size()));
    if (added) {
      if (index_of.size() > 256) return false;
      palette.insert(palette.end(), &image.rgb[3 * i], &image.rgb[3 * i + 3]);
    }
    indices[i] = it->second;
  }
  return true;
}

// Palette scanlines: filter type 0 (none), as the specification advises for palette images.
std::vector<std::uint8_t> unfiltered_rows(const Image& image,
                                          const std::vector<std::uint8_t>& indices) {
  const auto width = static_cast<std::size_t>(image.width);
  std::vector<std::uint8_t> out;
  out.reserve((width + 1) * static_cast<std::size_t>(image.height));
  for (std::size_t y = 0; y < static_cast<std::size_t>(image.height); ++y) {
    out.push_back(0);
    out.insert(out.end(), indices.begin() + static_cast<std::ptrdiff_t>(y * width),
               indices.begin() + static_cast<std::ptrdiff_t>((y + 1) * width));
  }
  return out;
}

}  // namespace

std::vector<std::uint8_t> encode_png(const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * image.height)
    throw Error(Exit::failure, fmt::format("encode_png: a {}x{} image needs {} bytes, not {}",
                                           image.width, image.height,
                                           3 * static_cast<std::size_t>(std::max(image.width, 0)) *
                                               static_cast<std::size_t>(std::max(image.height, 0)),
                                           image.rgb.size()));
  std::vector<std::uint8_t> out(kSignature.begin(), kSignature.end());
  std::vector<std::uint8_t> header;
  put_be32(header, static_cast<std::uint32_t>(image.width));
  put_be32(header, static_cast<std::uint32_t>(image.height));
  std::vector<std::uint8_t> palette, indices;
  const bool indexed = to_palette(image, palette, indices);
  // Bit depth 8, colour type 3 (palette) or 2 (RGB), deflate, adaptive filtering, no interlace.
  header.insert(header.end(), {8, static_cast<std::uint8_t>(indexed ? 3 : 2), 0, 0, 0});
  put_chunk(out, "IHDR", header);
  if (indexed) {
    put_chunk(out, "PLTE", palette);
    put_chunk(out, "IDAT", render::zlib_compress(unfiltered_rows(image, indices)));
  } else {
    put_chunk(out, "IDAT", render::zlib_compress(filter_rows(image)));
  }
  put_chunk(out, "IEND", {});
  return out;
}

void write_png(const std::filesystem::path& target, const Image& image) {
  const std::vector<std::uint8_t> bytes = encode_png(image);
  AtomicFile file(target);
  file.write(bytes.data(), bytes.size());
  file.commit();
}

}  // namespace g2s
