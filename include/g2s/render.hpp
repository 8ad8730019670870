// Offscreen pictures of meshes (src/render/), so that a reader can look at a mesh instead of
// reading its defect counts: a z-buffer rasteriser with flat shading, outside and inside in two
// colours (as the paper's Fig. 7: outside blue, inside yellow), boundary edges in red and
// non-manifold edges in magenta, drawn over the surface where they are visible; and a PNG writer
// of its own (deflate with fixed Huffman codes), so there is no image library to depend on.
// Shading is quantised to 64 levels, so a picture has at most 131 colours and is stored as a
// small palette PNG.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "g2s/types.hpp"

namespace g2s {

struct RenderOptions {
  int width = 800;  // pixels, 1 .. 16384 each
  int height = 600;
  // The camera looks at the mesh's bounding-box centre from this direction, orthographically, the
  // mesh filling about 94% of the frame. Azimuth turns about the up axis, counter-clockwise seen
  // from above; at 0 the camera sits on the axis after `up` in x, y, z order (up z: on +x; up y:
  // on +z; up x: on +y). Elevation is above the horizontal plane, in (-90, 90).
  double azimuth_deg = 30.0;
  double elevation_deg = 20.0;
  int up_axis = 2;  // 0 x, 1 y, 2 z
  // Boundary and non-manifold edges are drawn this many pixels wide (0 .. 8; 0: not drawn).
  // 1 keeps the surface visible where there are very many, as on merged raw scans.
  int edge_width = 2;
};

// An RGB picture: width * height pixels, 3 bytes each, rows top to bottom.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;
};

// What was drawn, for the CLI summary and the tests.
struct RenderReport {
  std::uint64_t triangles = 0;       // rasterised (degenerate ones included, they cover nothing)
  std::uint64_t boundary_edges = 0;  // edges in exactly 1 triangle, drawn red
  std::uint64_t non_manifold_edges = 0;  // edges in more than 2 triangles, drawn magenta
};

// Renders mesh (vertices are welded as given: edges are counted by vertex index) on a white
// background. Triangles indexing past mesh.xyz throw Error(bad_input); options out of range throw
// Error(usage). An empty mesh gives a white picture.
Image render_mesh(const IndexedMesh& mesh, const RenderOptions& options,
                  RenderReport* report = nullptr);

// The PNG file's bytes, 8 bits per sample, non-interlaced, one IDAT chunk: a palette image (one
// index a pixel, rows unfiltered) when there are at most 256 colours, as render_mesh's pictures
// have; otherwise RGB, each row filtered with the PNG filter (none, sub, up or Paeth) whose output
// has the smallest sum of magnitudes. Compressed in a zlib stream of one fixed-Huffman deflate
// block (LZ77 with hash chains). Error(failure) when rgb does not hold width * height pixels.
std::vector<std::uint8_t> encode_png(const Image& image);

// encode_png written through AtomicFile: complete at target or absent; Error(write_failed).
void write_png(const std::filesystem::path& target, const Image& image);

}  // namespace g2s
