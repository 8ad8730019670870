// Tests of the offscreen renderer and PNG writer (include/g2s/render.hpp, `g2s render`). The PNG
// is read back by an independent decoder written here from the specifications (PNG chunks with a
// bitwise CRC-32, zlib with Adler-32, stored and fixed-Huffman deflate blocks, the five row
// filters, palettes), so the writer's own tables are not trusted to check themselves.
#include "g2s/render.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "support/cli.hpp"
#include "support/temp_folder.hpp"

namespace {

using Bytes = std::vector<std::uint8_t>;

std::uint32_t bitwise_crc32(const std::uint8_t* data, std::size_t size) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= data[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

std::uint32_t be32(const Bytes& b, std::size_t at) {
  if (at + 4 > b.size()) throw std::runtime_error("truncated");
  return std::uint32_t{b[at]} << 24 | std::uint32_t{b[at + 1]} << 16 |
         std::uint32_t{b[at + 2]} << 8 | b[at + 3];
}

// RFC 1950/1951 inflate for the block types the writer may use: stored and fixed Huffman.
Bytes inflate_zlib(const Bytes& z) {
  if (z.size() < 6 || (z[0] & 0x0F) != 8 || ((z[0] << 8) | z[1]) % 31 != 0 || (z[1] & 0x20))
    throw std::runtime_error("bad zlib header");
  std::size_t bit = 16;
  auto get = [&](int n) {
    std::uint32_t v = 0;
    for (int i = 0; i < n; ++i, ++bit) {
      if (bit / 8 >= z.size()) throw std::runtime_error("deflate stream runs past its end");
      v |= static_cast<std::uint32_t>((z[bit / 8] >> (bit % 8)) & 1) << i;
    }
    return v;
  };
  auto huffman = [&](int n) {  // n bits, most significant first
    std::uint32_t v = 0;
    for (int i = 0; i < n; ++i) v = v << 1 | get(1);
    return v;
  };
  static constexpr std::array<int, 29> kLenBase{3,  4,  5,  6,   7,   8,   9,   10,  11, 13,
                                                15, 17, 19, 23,  27,  31,  35,  43,  51, 59,
                                                67, 83, 99, 115, 131, 163, 195, 227, 258};
  static constexpr std::array<int, 30> kDistBase{
      1,   2,   3,   4,   5,   7,    9,    13,   17,   25,   33,   49,   65,    97,    129,
      193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
  Bytes out;
  for (bool last = false; !last;) {
    last = get(1) != 0;
    const std::uint32_t type = get(2);
    if (type == 0) {
      bit = (bit + 7) / 8 * 8;
      const std::uint32_t len = get(16), nlen = get(16);
      if ((len ^ 0xFFFFu) != nlen) throw std::runtime_error("stored block: LEN != ~NLEN");
      for (std::uint32_t i = 0; i < len; ++i) out.push_back(static_cast<std::uint8_t>(get(8)));
      continue;
    }
    if (type != 1) throw std::runtime_error("block type " + std::to_string(type));
    for (;;) {
      std::uint32_t code = huffman(7), symbol;
      if (code <= 23) {
        symbol = 256 + code;
      } else {
        code = code << 1 | get(1);
        if (code >= 0x30 && code <= 0xBF) {
          symbol = code - 0x30;
        } else if (code >= 0xC0 && code <= 0xC7) {
          symbol = 280 + code - 0xC0;
        } else {
          symbol = 144 + (code << 1 | get(1)) - 0x190;
        }
      }
      if (symbol < 256) {
        out.push_back(static_cast<std::uint8_t>(symbol));
        continue;
      }
      if (symbol == 256) break;
      const std::uint32_t l = symbol - 257;
      if (l >= 29) throw std::runtime_error("bad length symbol");
      const int extra = l < 8 || l == 28 ? 0 : static_cast<int>((l - 4) / 4);
      const std::size_t length = kLenBase[l] + get(extra);
      const std::uint32_t d = huffman(5);
      if (d >= 30) throw std::runtime_error("bad distance symbol");
      const int dextra = d < 4 ? 0 : static_cast<int>((d - 2) / 2);
      const std::size_t distance = kDistBase[d] + get(dextra);
      if (distance > out.size()) throw std::runtime_error("distance before the start");
      for (std::size_t i = 0; i < length; ++i) out.push_back(out[out.size() - distance]);
    }
  }
  const std::size_t end = (bit + 7) / 8;
  std::uint32_t a = 1, b = 0;
  for (const std::uint8_t byte : out) {
    a = (a + byte) % 65521;
    b = (b + a) % 65521;
  }
  if (be32(z, end) != (b << 16 | a)) throw std::runtime_error("Adler-32 mismatch");
  return out;
}

// Decodes an 8-bit RGB or palette PNG into an Image, checking the signature and every CRC.
g2s::Image decode_png(const Bytes& png) {
  const Bytes signature{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (png.size() < 8 || !std::equal(signature.begin(), signature.end(), png.begin()))
    throw std::runtime_error("bad signature");
  g2s::Image image;
  int colour_type = -1;
  Bytes palette, idat;
  bool ended = false;
  for (std::size_t at = 8; at < png.size();) {
    const std::uint32_t length = be32(png, at);
    if (at + 12 + length > png.size()) throw std::runtime_error("chunk runs past the end");
    const std::string type(png.begin() + static_cast<std::ptrdiff_t>(at + 4),
                           png.begin() + static_cast<std::ptrdiff_t>(at + 8));
    if (bitwise_crc32(&png[at + 4], 4 + length) != be32(png, at + 8 + length))
      throw std::runtime_error("CRC mismatch in " + type);
    const Bytes data(png.begin() + static_cast<std::ptrdiff_t>(at + 8),
                     png.begin() + static_cast<std::ptrdiff_t>(at + 8 + length));
    if (type == "IHDR") {
      image.width = static_cast<int>(be32(data, 0));
      image.height = static_cast<int>(be32(data, 4));
      if (data[8] != 8 || data[10] != 0 || data[11] != 0 || data[12] != 0)
        throw std::runtime_error("unexpected IHDR");
      colour_type = data[9];
    } else if (type == "PLTE") {
      palette = data;
    } else if (type == "IDAT") {
      idat.insert(idat.end(), data.begin(), data.end());
    } else if (type == "IEND") {
      ended = at + 12 + length == png.size();
    }
    at += 12 + length;
  }
  if (!ended) throw std::runtime_error("no IEND at the end");
  if (colour_type != 2 && colour_type != 3) throw std::runtime_error("not RGB or palette");
  const std::size_t bpp = colour_type == 2 ? 3 : 1;
  const std::size_t stride = bpp * static_cast<std::size_t>(image.width);
  const Bytes raw = inflate_zlib(idat);
  if (raw.size() != (stride + 1) * static_cast<std::size_t>(image.height))
    throw std::runtime_error("image data has the wrong size");
  Bytes pixels(stride * static_cast<std::size_t>(image.height));
  for (std::size_t y = 0; y < static_cast<std::size_t>(image.height); ++y) {
    const std::uint8_t filter = raw[y * (stride + 1)];
    for (std::size_t x = 0; x < stride; ++x) {
      const int a = x >= bpp ? pixels[y * stride + x - bpp] : 0;
      const int b = y > 0 ? pixels[(y - 1) * stride + x] : 0;
      const int c = x >= bpp && y > 0 ? pixels[(y - 1) * stride + x - bpp] : 0;
      int predictor = 0;
      if (filter == 1) predictor = a;
      if (filter == 2) predictor = b;
      if (filter == 3) predictor = (a + b) / 2;
      if (filter == 4) {
        const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
        predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      if (filter > 4) throw std::runtime_error("bad filter type");
      pixels[y * stride + x] = static_cast<std::uint8_t>(raw[y * (stride + 1) + 1 + x] + predictor);
    }
  }
  if (colour_type == 2) {
    image.rgb = pixels;
  } else {
    for (const std::uint8_t index : pixels) {
      if (3u * index + 3 > palette.size()) throw std::runtime_error("index past the palette");
      image.rgb.insert(image.rgb.end(), &palette[3u * index], &palette[3u * index + 3]);
    }
  }
  return image;
}

struct Census {
  int white = 0, blue = 0, yellow = 0, red = 0, magenta = 0;
};

// Counts pixels by the renderer's colours: background, outside (blue), inside (yellow),
// boundary edges (red), non-manifold edges (magenta).
Census census(const g2s::Image& image) {
  Census c;
  for (std::size_t i = 0; i < image.rgb.size(); i += 3) {
    const int r = image.rgb[i], g = image.rgb[i + 1], b = image.rgb[i + 2];
    if (r == 255 && g == 255 && b == 255)
      ++c.white;
    else if (r == 220 && g == 20 && b == 20)
      ++c.red;
    else if (r == 200 && g == 0 && b == 200)
      ++c.magenta;
    else if (b > r)
      ++c.blue;
    else if (r > b && g > b)
      ++c.yellow;
  }
  return c;
}

g2s::IndexedMesh tetrahedron() {  // closed, every triangle counter-clockwise seen from outside
  return {{1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1}, {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}}};
}

g2s::Image render_and_read_back(const g2s::IndexedMesh& mesh, const g2s::RenderOptions& options,
                                g2s::RenderReport* report = nullptr) {
  const g2s::Image image = g2s::render_mesh(mesh, options, report);
  const g2s::Image read = decode_png(g2s::encode_png(image));
  EXPECT_EQ(read.width, options.width);
  EXPECT_EQ(read.height, options.height);
  EXPECT_EQ(read.rgb, image.rgb);
  return read;
}

TEST(Render, ClosedMeshShowsItsOutsideAndNoEdges) {
  g2s::RenderOptions options;
  options.width = 160;
  options.height = 120;
  g2s::RenderReport report;
  const Census c = census(render_and_read_back(tetrahedron(), options, &report));
  EXPECT_EQ(report.triangles, 4u);
  EXPECT_EQ(report.boundary_edges, 0u);
  EXPECT_EQ(report.non_manifold_edges, 0u);
  EXPECT_GT(c.blue, 160 * 120 / 5);
  EXPECT_GT(c.white, 160 * 120 / 5);
  EXPECT_EQ(c.yellow + c.red + c.magenta, 0);
  EXPECT_EQ(c.white + c.blue, 160 * 120);
}

TEST(Render, InsideOutMeshIsYellow) {
  g2s::IndexedMesh mesh = tetrahedron();
  for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  g2s::RenderOptions options;
  options.width = 80;
  options.height = 60;
  const Census c = census(render_and_read_back(mesh, options));
  EXPECT_GT(c.yellow, 80 * 60 / 5);
  EXPECT_EQ(c.blue, 0);
}

TEST(Render, BoundaryEdgesAreRedAndNonManifoldEdgesMagenta) {
  // A square of two triangles (4 boundary edges), seen from above at an angle.
  g2s::IndexedMesh square{{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, {{0, 1, 2}, {0, 2, 3}}};
  g2s::RenderOptions options;
  options.width = 100;
  options.height = 80;
  options.elevation_deg = 50;
  g2s::RenderReport report;
  Census c = census(render_and_read_back(square, options, &report));
  EXPECT_EQ(report.boundary_edges, 4u);
  EXPECT_EQ(report.non_manifold_edges, 0u);
  EXPECT_GT(c.red, 100);
  EXPECT_GT(c.blue, 500);
  EXPECT_EQ(c.magenta, 0);
  // A third triangle on edge 0-2 makes it non-manifold.
  square.xyz.insert(square.xyz.end(), {0.5, 0.5, 1});
  square.triangles.push_back({0, 2, 4});
  c = census(render_and_read_back(square, options, &report));
  EXPECT_EQ(report.non_manifold_edges, 1u);
  EXPECT_EQ(report.boundary_edges, 6u);
  EXPECT_GT(c.magenta, 10);
  // Edges can be drawn thinner, or not at all.
  options.edge_width = 1;
  const Census thin = census(render_and_read_back(square, options));
  EXPECT_GT(thin.red, 50);
  EXPECT_LT(thin.red, c.red);
  options.edge_width = 0;
  const Census none = census(render_and_read_back(square, options));
  EXPECT_EQ(none.red + none.magenta, 0);
}

// A boundary edge hidden behind the surface is not drawn: a square with a far-away twin behind
// it (seen head-on, the front one covers the back one entirely).
TEST(Render, HiddenEdgesAreNotDrawn) {
  const g2s::IndexedMesh front{{-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, {{0, 1, 2}, {0, 2, 3}}};
  g2s::IndexedMesh both = front;
  both.xyz.insert(both.xyz.end(), {-0.5, -0.5, -5, 0.5, -0.5, -5, 0.5, 0.5, -5, -0.5, 0.5, -5});
  both.triangles.insert(both.triangles.end(), {{4, 5, 6}, {4, 6, 7}});
  g2s::RenderOptions options;
  options.width = 90;
  options.height = 90;
  options.elevation_deg = 89;  // looking down the z axis
  g2s::RenderReport report;
  const Census c = census(render_and_read_back(both, options, &report));
  EXPECT_EQ(report.boundary_edges, 8u);
  EXPECT_EQ(c.red, census(render_and_read_back(front, options)).red);
}

TEST(Render, RejectsBadOptionsAndIndices) {
  auto code = [](const g2s::IndexedMesh& mesh, const g2s::RenderOptions& options) {
    try {
      g2s::render_mesh(mesh, options);
    } catch (const g2s::Error& e) {
      return static_cast<int>(e.code());
    }
    return 0;
  };
  g2s::RenderOptions options;
  EXPECT_EQ(code(tetrahedron(), options), 0);
  g2s::IndexedMesh broken = tetrahedron();
  broken.triangles.push_back({0, 1, 4});
  EXPECT_EQ(code(broken, options), static_cast<int>(g2s::Exit::bad_input));
  options.width = 0;
  EXPECT_EQ(code(tetrahedron(), options), static_cast<int>(g2s::Exit::usage));
  options.width = 10;
  options.elevation_deg = 90;
  EXPECT_EQ(code(tetrahedron(), options), static_cast<int>(g2s::Exit::usage));
  options.elevation_deg = 0;
  options.edge_width = 9;
  EXPECT_EQ(code(tetrahedron(), options), static_cast<int>(g2s::Exit::usage));
  options.edge_width = 2;
  options.up_axis = 3;
  EXPECT_EQ(code(tetrahedron(), options), static_cast<int>(g2s::Exit::usage));
  // An empty mesh is a white picture.
  options.up_axis = 1;
  const Census c = census(render_and_read_back({}, options));
  EXPECT_EQ(c.white, 10 * 600);
}

// More than 256 colours: RGB with row filters, read back exactly; long runs exercise matches of
// every length and distances across rows.
TEST(Render, PngOfAManyColouredImageRoundTrips) {
  g2s::Image image;
  image.width = 300;
  image.height = 40;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const bool stripe = (x / 50) % 2 == 0;
      image.rgb.push_back(static_cast<std::uint8_t>(stripe ? x : 255));
      image.rgb.push_back(static_cast<std::uint8_t>(stripe ? y * 6 : 255));
      image.rgb.push_back(static_cast<std::uint8_t>((x * 7 + y * 13) % 256));
    }
  }
  const Bytes png = g2s::encode_png(image);
  EXPECT_EQ(png[8 + 8 + 9], 2);  // IHDR colour type: RGB
  const g2s::Image read = decode_png(png);
  EXPECT_EQ(read.width, 300);
  EXPECT_EQ(read.height, 40);
  EXPECT_EQ(read.rgb, image.rgb);
  g2s::Image wrong = image;
  wrong.rgb.pop_back();
  EXPECT_THROW(g2s::encode_png(wrong), g2s::Error);
}

TEST(Render, CommandLine) {
  const g2s::test_support::TempFolder folder("g2s-render-cli");
  const std::filesystem::path& dir = folder.path();
  const g2s::IndexedMesh mesh = tetrahedron();
  g2s::write_mesh(dir / "tet.ply", mesh.xyz, mesh.triangles, g2s::MeshFormat::ply_binary);
  const std::string in = (dir / "tet.ply").string();
  const std::string out = (dir / "tet.png").string();
  auto run = [&](const std::vector<std::string>& args, int code) {
    g2s::test_support::cli_output(dir, args, code);
  };
  run({"render", in, "-o", out, "--size", "120x90", "--view", "45,30", "--up", "y"}, 0);
  const std::string png = g2s::test_support::file_bytes(dir / "tet.png");
  const g2s::Image image = decode_png(Bytes(png.begin(), png.end()));
  EXPECT_EQ(image.width, 120);
  EXPECT_EQ(image.height, 90);
  EXPECT_GT(census(image).blue, 1000);
  run({"render", in, "-o", out, "--size", "120"}, 2);
  run({"render", in, "-o", out, "--view", "10,95"}, 2);
  run({"render", in, "-o", out, "--up", "w"}, 2);
  run({"render", (dir / "missing.ply").string(), "-o", out}, 3);
}

}  // namespace
