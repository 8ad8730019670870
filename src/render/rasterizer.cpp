// The offscreen renderer (include/g2s/render.hpp: render_mesh): orthographic camera fitted to the
// mesh, a z-buffer, flat shading with one light near the camera, outside and inside coloured
// apart so orientation can be seen (as the paper's Fig. 7), then boundary and non-manifold edges
// drawn on top where the surface does not hide them. Pixels are sampled at their centres, no
// antialiasing: the pictures stay exact and compress well.
#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include "common/vec3.hpp"
#include "g2s/error.hpp"
#include "g2s/render.hpp"

namespace g2s {
namespace {

constexpr int kMaxSide = 16384;
constexpr int kMaxEdgeWidth = 8;
constexpr double kFill = 0.94;  // share of the frame the mesh's projection spans
constexpr std::array<double, 3> kOutside{110, 150, 220};          // blue
constexpr std::array<double, 3> kInside{230, 190, 80};            // yellow
constexpr std::array<std::uint8_t, 3> kBoundary{220, 20, 20};     // red
constexpr std::array<std::uint8_t, 3> kNonManifold{200, 0, 200};  // magenta
constexpr double kAmbient = 0.3;
// Shades per side: 2 x 64 + background, red and magenta keep a picture within a PNG palette.
constexpr int kShadeLevels = 64;

struct Camera {
  Vec3 centre, right, up, toward_eye;
};

Vec3 axis(int a) {
  return {a == 0 ? 1.0 : 0.0, a == 1 ? 1.0 : 0.0, a == 2 ? 1.0 : 0.0};
}

Camera make_camera(const RenderOptions& o, const Vec3& centre) {
  // (first, second, up) is right-handed: up z -> (x, y), up y -> (z, x), up x -> (y, z).
  const Vec3 first = axis((o.up_axis + 1) % 3), second = axis((o.up_axis + 2) % 3);
  const Vec3 up = axis(o.up_axis);
  const double az = o.azimuth_deg * std::numbers::pi / 180.0;
  const double el = o.elevation_deg * std::numbers::pi / 180.0;
  const Vec3 horizontal = first * std::cos(az) + second * std::sin(az);
  Camera c;
  c.centre = centre;
  c.toward_eye = horizontal * std::cos(el) + up * std::sin(el);
  c.right = second * std::cos(az) - first * std::sin(az);
  c.up = cross(c.right, c.toward_eye * -1.0);
  return c;
}

void check_options(const RenderOptions& o) {
  if (o.width < 1 || o.width > kMaxSide || o.height < 1 || o.height > kMaxSide)
    throw Error(Exit::usage, fmt::format("render: size must be 1..{} in each direction, not {}x{}",
                                         kMaxSide, o.width, o.height));
  if (!std::isfinite(o.azimuth_deg) || !std::isfinite(o.elevation_deg) ||
      !(std::abs(o.elevation_deg) < 90.0))
    throw Error(Exit::usage,
                fmt::format("render: view needs a finite azimuth and an elevation in (-90, 90), "
                            "not {},{}",
                            o.azimuth_deg, o.elevation_deg));
  if (o.edge_width < 0 || o.edge_width > kMaxEdgeWidth)
    throw Error(Exit::usage, fmt::format("render: edge width must be 0..{} pixels, not {}",
                                         kMaxEdgeWidth, o.edge_width));
  if (o.up_axis < 0 || o.up_axis > 2)
    throw Error(Exit::usage, fmt::format("render: up axis must be 0, 1 or 2, not {}", o.up_axis));
}

// Edges used by one triangle and by more than two, as vertex pairs, in sorted order.
void classify_edges(const IndexedMesh& mesh, std::vector<std::array<Index, 2>>& boundary,
                    std::vector<std::array<Index, 2>>& non_manifold) {
  std::vector<std::uint64_t> keys;
  keys.reserve(3 * mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const Index u = t[k], v = t[(k + 1) % 3];
      if (u == v) continue;
      keys.push_back(std::uint64_t{std::min(u, v)} << 32 | std::max(u, v));
    }
  }
  std::sort(keys.begin(), keys.end());
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i;
    while (j < keys.size() && keys[j] == keys[i]) ++j;
    const std::array<Index, 2> edge{static_cast<Index>(keys[i] >> 32),
                                    static_cast<Index>(keys[i] & 0xFFFFFFFFu)};
    if (j - i == 1) boundary.push_back(edge);
    if (j - i > 2) non_manifold.push_back(edge);
    i = j;
  }
}

class Canvas {
 public:
  Canvas(int width, int height)
      : width_(width),
        height_(height),
        depth_(static_cast<std::size_t>(width) * height, -std::numeric_limits<double>::infinity()) {
    image_.width = width;
    image_.height = height;
    image_.rgb.assign(3 * depth_.size(), 255);
  }

  // Fills the triangle of screen points (x, y, depth: larger is nearer) where it is nearest.
  void triangle(const Vec3& a, const Vec3& b, const Vec3& c,
                const std::array<std::uint8_t, 3>& rgb) {
    const double area = edge(a, b, c);
    if (area == 0.0) return;  // seen edge-on
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x, b.x, c.x}))));
    const int x1 = std::min(width_ - 1, static_cast<int>(std::ceil(std::max({a.x, b.x, c.x}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y, b.y, c.y}))));
    const int y1 = std::min(height_ - 1, static_cast<int>(std::ceil(std::max({a.y, b.y, c.y}))));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const Vec3 p{x + 0.5, y + 0.5, 0.0};
        const double wa = edge(b, c, p) / area, wb = edge(c, a, p) / area,
                     wc = edge(a, b, p) / area;
        if (wa < 0.0 || wb < 0.0 || wc < 0.0) continue;
        plot(x, y, wa * a.z + wb * b.z + wc * c.z, 0.0, rgb, true);
      }
    }
  }

  // Draws the segment a-b `width` pixels wide where it lies no more than slack behind the
  // surface.
  void line(const Vec3& a, const Vec3& b, int width, double slack,
            const std::array<std::uint8_t, 3>& rgb) {
    const int steps =
        1 + static_cast<int>(std::ceil(std::max(std::abs(b.x - a.x), std::abs(b.y - a.y))));
    for (int s = 0; s <= steps; ++s) {
      const double t = static_cast<double>(s) / steps;
      const Vec3 p = a + (b - a) * t;
      const int x = static_cast<int>(std::floor(p.x)), y = static_cast<int>(std::floor(p.y));
      for (int dy = 0; dy < width; ++dy)
        for (int dx = 0; dx < width; ++dx) plot(x + dx, y + dy, p.z, slack, rgb, false);
    }
  }

  Image take() { return std::move(image_); }

 private:
  static double edge(const Vec3& a, const Vec3& b, const Vec3& p) {
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
  }

  void plot(int x, int y, double depth, double slack, const std::array<std::uint8_t, 3>& rgb,
            bool write_depth) {
    if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
    const std::size_t i = static_cast<std::size_t>(y) * width_ + x;
    if (depth + slack < depth_[i]) return;
    if (write_depth) depth_[i] = depth;
    std::copy(rgb.begin(), rgb.end(), &image_.rgb[3 * i]);
  }

  int width_, height_;
  std::vector<double> depth_;
  Image image_;
};

}  // namespace

Image render_mesh(const IndexedMesh& mesh, const RenderOptions& options, RenderReport* report) {
  check_options(options);
  const std::size_t nv = mesh.vertex_count();
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};
  bool any = false;
  for (const Triangle& t : mesh.triangles) {
    for (const Index v : t) {
      if (v >= nv)
        throw Error(Exit::bad_input, fmt::format("render: a triangle uses vertex {} of {}", v, nv));
      const Vec3 p{mesh.xyz[3 * v], mesh.xyz[3 * v + 1], mesh.xyz[3 * v + 2]};
      lo = any ? Vec3{std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)} : p;
      hi = any ? Vec3{std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)} : p;
      any = true;
    }
  }
  Canvas canvas(options.width, options.height);
  RenderReport counts;
  counts.triangles = mesh.triangles.size();
  if (!any) {
    if (report) *report = counts;
    return canvas.take();
  }
  const Camera cam = make_camera(options, (lo + hi) * 0.5);

  // Camera coordinates of every vertex, then the scale that fits their extent into the frame.
  std::vector<Vec3> view(nv);
  double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo, y_lo = x_lo, y_hi = -x_lo;
  for (const Triangle& t : mesh.triangles) {
    for (const Index v : t) {
      const Vec3 d = Vec3{mesh.xyz[3 * v], mesh.xyz[3 * v + 1], mesh.xyz[3 * v + 2]} - cam.centre;
      view[v] = {dot(d, cam.right), dot(d, cam.up), dot(d, cam.toward_eye)};
      x_lo = std::min(x_lo, view[v].x), x_hi = std::max(x_hi, view[v].x);
      y_lo = std::min(y_lo, view[v].y), y_hi = std::max(y_hi, view[v].y);
    }
  }
  const double w = options.width, h = options.height;
  double scale =
      kFill * std::min(x_hi > x_lo ? w / (x_hi - x_lo) : w, y_hi > y_lo ? h / (y_hi - y_lo) : h);
  if (!(x_hi > x_lo) && !(y_hi > y_lo)) scale = 1.0;
  const double x_mid = 0.5 * (x_lo + x_hi), y_mid = 0.5 * (y_lo + y_hi);
  auto screen = [&](Index v) {
    return Vec3{0.5 * w + (view[v].x - x_mid) * scale, 0.5 * h - (view[v].y - y_mid) * scale,
                view[v].z};
  };

  // A light above and left of the camera, so that faces turned from it are darker.
  const Vec3 light = normalized(cam.toward_eye + cam.up * 0.6 - cam.right * 0.4);
  for (const Triangle& t : mesh.triangles) {
    const Vec3 a{mesh.xyz[3 * t[0]], mesh.xyz[3 * t[0] + 1], mesh.xyz[3 * t[0] + 2]};
    const Vec3 b{mesh.xyz[3 * t[1]], mesh.xyz[3 * t[1] + 1], mesh.xyz[3 * t[1] + 2]};
    const Vec3 c{mesh.xyz[3 * t[2]], mesh.xyz[3 * t[2] + 1], mesh.xyz[3 * t[2] + 2]};
    Vec3 normal = normalized(cross(b - a, c - a));
    const bool outside = dot(normal, cam.toward_eye) >= 0.0;
    if (!outside) normal = normal * -1.0;
    const double lit = std::round(std::max(0.0, dot(normal, light)) * (kShadeLevels - 1));
    const double shade = kAmbient + (1.0 - kAmbient) * lit / (kShadeLevels - 1);
    const std::array<double, 3>& base = outside ? kOutside : kInside;
    std::array<std::uint8_t, 3> rgb;
    for (int k = 0; k < 3; ++k) rgb[k] = static_cast<std::uint8_t>(std::lround(base[k] * shade));
    canvas.triangle(screen(t[0]), screen(t[1]), screen(t[2]), rgb);
  }

  std::vector<std::array<Index, 2>> boundary, non_manifold;
  classify_edges(mesh, boundary, non_manifold);
  counts.boundary_edges = boundary.size();
  counts.non_manifold_edges = non_manifold.size();
  // An edge shows when it is within two pixels' depth of the nearest surface there.
  const double slack = 2.0 / scale;
  const int width = options.edge_width;
  for (const auto& e : boundary) canvas.line(screen(e[0]), screen(e[1]), width, slack, kBoundary);
  for (const auto& e : non_manifold)
    canvas.line(screen(e[0]), screen(e[1]), width, slack, kNonManifold);
  if (report) *report = counts;
  return canvas.take();
}

}  // namespace g2s
