// `g2s render MESH -o OUT.png [--size WxH] [--view AZIMUTH,ELEVATION] [--up x|y|z]
// [--edge-width N]`: a picture of a mesh for people (docs, reports): flat-shaded, outside blue and
// inside yellow, boundary edges red, non-manifold edges magenta. Unreadable meshes exit 3, bad
// options 2.
#include <fmt/core.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>

#include "cli_checks.hpp"
#include "commands.hpp"
#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/render.hpp"

namespace g2s::cli {
namespace {

struct RenderArgs {
  std::string mesh;
  std::string output;
  std::string size = "800x600";
  std::string view = "30,20";
  std::string up = "z";
  int edge_width = 2;
};

// "A<sep>B" -> two numbers; false when the text is anything else.
template <class T>
bool parse_pair(const std::string& text, char sep, T& a, T& b) {
  const std::size_t at = text.find(sep);
  if (at == std::string::npos) return false;
  const char* end = text.data() + text.size();
  const auto [p1, e1] = std::from_chars(text.data(), text.data() + at, a);
  const auto [p2, e2] = std::from_chars(text.data() + at + 1, end, b);
  return e1 == std::errc() && p1 == text.data() + at && e2 == std::errc() && p2 == end;
}

void run_render(const RenderArgs& args) {
  RenderOptions options;
  if (!parse_pair(args.size, 'x', options.width, options.height))
    throw Error(Exit::usage,
                fmt::format("render: --size expects WIDTHxHEIGHT, not '{}'", args.size));
  if (!parse_pair(args.view, ',', options.azimuth_deg, options.elevation_deg))
    throw Error(
        Exit::usage,
        fmt::format("render: --view expects AZIMUTH,ELEVATION in degrees, not '{}'", args.view));
  require_extension(args.output, ".png", "the picture");
  refuse_same_file({args.mesh}, args.output, "-o");
  options.up_axis = args.up[0] - 'x';
  options.edge_width = args.edge_width;
  IndexedMesh mesh = read_mesh(args.mesh);
  // A vertex at NaN or Inf would stretch the view to nothing: such triangles are left out.
  const auto finite = [&mesh](Index v) {
    return static_cast<std::size_t>(v) < mesh.vertex_count() && std::isfinite(mesh.xyz[3 * v]) &&
           std::isfinite(mesh.xyz[3 * v + 1]) && std::isfinite(mesh.xyz[3 * v + 2]);
  };
  const std::size_t given = mesh.triangles.size();
  std::erase_if(mesh.triangles, [&](const Triangle& t) {
    return static_cast<std::size_t>(t[0]) < mesh.vertex_count() &&
           static_cast<std::size_t>(t[1]) < mesh.vertex_count() &&
           static_cast<std::size_t>(t[2]) < mesh.vertex_count() &&
           !(finite(t[0]) && finite(t[1]) && finite(t[2]));
  });
  if (mesh.triangles.size() < given) {
    fmt::print(stderr,
               "g2s: warning: {}: {} of {} triangles have a vertex at NaN or Inf; drawn without "
               "them\n",
               args.mesh, given - mesh.triangles.size(), given);
  }
  RenderReport report;
  const Image image = render_mesh(mesh, options, &report);
  write_png(args.output, image);
  fmt::print(stderr,
             "g2s render: {}: {} triangles, {} boundary edges, {} non-manifold edges; wrote {} "
             "({}x{}, {} bytes)\n",
             args.mesh, report.triangles, report.boundary_edges, report.non_manifold_edges,
             args.output, image.width, image.height, std::filesystem::file_size(args.output));
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Render a triangle mesh (STL or PLY) to PNG: orthographic view of the whole mesh,\n"
      "flat-shaded, outside blue and inside yellow (by triangle orientation), boundary edges\n"
      "red and non-manifold edges magenta where the surface does not hide them.");
  cmd->add_option("MESH", args->mesh, "Mesh to render (.stl binary or ASCII, .ply)")->required();
  cmd->add_option("-o,--output", args->output, "Output picture (PNG)")->required();
  cmd->add_option("--size", args->size, "Picture size in pixels, WIDTHxHEIGHT (1..16384 each)")
      ->capture_default_str();
  cmd->add_option("--view", args->view,
                  "Camera direction in degrees: azimuth about the up axis (0: from the next axis,\n"
                  "up z: from +x, up y: from +z, up x: from +y), elevation in (-90, 90)")
      ->capture_default_str();
  cmd->add_option("--edge-width", args->edge_width,
                  "Width of the boundary and non-manifold edges in pixels (0: not drawn)")
      ->capture_default_str()
      ->check(CLI::Range(0, 8));
  cmd->add_option("--up", args->up, "The axis that points up in the picture")
      ->capture_default_str()
      ->check(CLI::IsMember({"x", "y", "z"}));
  cmd->callback([args] { run_render(*args); });
}

}  // namespace g2s::cli
