// `g2s synth SHAPE --points N -o OUT.ply [--noise S] [--outliers F] [--seed K]`: writes an
// evenly sampled analytic shape as binary PLY, for tests, the demo and benchmarks; streamed, so
// 100M points need no more memory than 1M. `g2s synth --from CLOUD -o OUT.ply [--noise S]
// [--outliers F] [--seed K]` perturbs a measured cloud the same way instead (the paper's noise
// and outlier experiments). Bad values exit 2 (CLI11 or g2s::Error(usage)).
#include <fmt/core.h>

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <system_error>

#include "cli_checks.hpp"
#include "commands.hpp"
#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/synth.hpp"

namespace g2s::cli {
namespace {

struct SynthArgs {
  std::string shape;
  std::string from;
  std::uint64_t points = 0;
  std::string output;
  double noise = 0.0;
  double outliers = 0.0;
  std::uint64_t seed = 1;
};

// "250000", "500k", "2M", "1.5G" -> the whole number, written back as digits for CLI11 to
// convert. Returns an error message, or "" when the text was understood.
std::string expand_count(std::string& text) {
  double scale = 1.0;
  std::string number = text;
  if (!number.empty()) {
    switch (number.back()) {
      case 'k':
      case 'K':
        scale = 1e3;
        break;
      case 'm':
      case 'M':
        scale = 1e6;
        break;
      case 'g':
      case 'G':
        scale = 1e9;
        break;
      default:
        break;
    }
    if (scale != 1.0) number.pop_back();
  }
  std::string error =
      "expected a positive whole number, optionally with a suffix k, M or "
      "G (500k, 2M, 1.5G), not '" +
      text + "'";
  if (number.empty() || number.find_first_not_of("0123456789.") != std::string::npos) return error;
  double mantissa = 0.0;
  const auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), mantissa);
  if (ec != std::errc() || end != number.data() + number.size()) return error;
  const double value = mantissa * scale;
  if (!(value >= 1.0) || value > 0x1.0p40 || value != std::floor(value)) return error;
  text = std::to_string(static_cast<std::uint64_t>(value));
  return "";
}

// Reads CLOUD, adds the noise and outliers and writes float PLY (in memory: the spacing needs
// every point).
void run_perturb(const SynthArgs& args) {
  PerturbOptions options;
  options.noise = args.noise;
  options.outliers = args.outliers;
  options.seed = args.seed;
  const auto start = std::chrono::steady_clock::now();
  const PointCloud cloud = read_points(args.from);
  PerturbReport report;
  PointCloud out;
  try {
    out = perturb_cloud(cloud, options, &report);
  } catch (const Error& e) {
    throw Error(e.code(), fmt::format("{}: {}", args.from, e.what()));  // name the cloud
  }
  // The output holds floats: a coordinate beyond them would be written as an infinity.
  for (const double v : out.xyz) {
    if (!std::isfinite(static_cast<float>(v))) {
      throw Error(Exit::bad_input,
                  fmt::format("{}: a coordinate of {:.6g} is beyond the 32-bit floats synth "
                              "writes (±3.4e38); nothing written",
                              args.from, v));
    }
  }
  PlyPointWriter writer(args.output, out.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    writer.add(static_cast<float>(out.xyz[3 * i]), static_cast<float>(out.xyz[3 * i + 1]),
               static_cast<float>(out.xyz[3 * i + 2]));
  }
  writer.finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print(stderr,
             "g2s synth: {} {} points + {} outliers, spacing {:.6g}, noise sigma {:.6g}, seed {}, "
             "wrote {} in {:.2f} s\n",
             args.from, cloud.size(), report.outliers, report.spacing, report.sigma, args.seed,
             args.output, seconds);
}

void run_synth(const SynthArgs& args) {
  require_extension(args.output, ".ply", "a synthetic cloud");
  if (!args.from.empty()) refuse_same_file({args.from}, args.output, "-o");
  if (!args.from.empty()) {
    run_perturb(args);
    return;
  }
  if (args.shape.empty() || args.points == 0)
    throw Error(Exit::usage, "synth: give a SHAPE and --points, or --from CLOUD");
  const auto shape = synth_shape_from_name(args.shape);
  if (!shape) throw Error(Exit::usage, fmt::format("unknown shape '{}'", args.shape));
  SynthOptions options;
  options.shape = *shape;
  options.points = args.points;
  options.noise = args.noise;
  options.outliers = args.outliers;
  options.seed = args.seed;
  const auto start = std::chrono::steady_clock::now();
  write_synthetic_cloud(args.output, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto outliers =
      static_cast<std::uint64_t>(std::llround(args.outliers * static_cast<double>(args.points)));
  fmt::print(stderr,
             "g2s synth: {} {} points + {} outliers, spacing {:.6g}, noise sigma {:.6g}, seed {}, "
             "wrote {} in {:.2f} s\n",
             args.shape, args.points, outliers, synth_spacing(options),
             args.noise * synth_spacing(options), args.seed, args.output, seconds);
}

}  // namespace

void add_synth_command(CLI::App& app) {
  auto args = std::make_shared<SynthArgs>();
  CLI::App* cmd = app.add_subcommand(
      "synth",
      "Write a synthetic point cloud as binary PLY (float x, y, z): an analytic shape sampled\n"
      "evenly like a good scan (one jittered point per near-square cell), with optional Gaussian\n"
      "noise and uniform outliers. Deterministic for a seed; streamed in bounded memory.\n"
      "Shapes: sphere (r 1), torus (R 1, r 0.35), cube (edge 2), plate (2 x 2 x 0.05, closed),\n"
      "uneven (unit sphere, density 1:16 pole to pole), terrain (open height field over [0,1]^2).\n"
      "With --from CLOUD instead of SHAPE: the cloud's points (in their order) with the noise,\n"
      "then the outliers in its bounding box; sigma is relative to its exact mean\n"
      "nearest-neighbour spacing. Written as float, like the shapes.");
  CLI::Option* shape =
      cmd->add_option("SHAPE", args->shape, "sphere, torus, cube, plate, uneven or terrain")
          ->check(CLI::IsMember({"sphere", "torus", "cube", "plate", "uneven", "terrain"}));
  CLI::Option* points =
      cmd->add_option("--points,-n", args->points,
                      "Surface points, exactly (suffixes k, M, G: 500k, 2M); with SHAPE")
          ->transform(CLI::Validator(expand_count, "N[k|M|G]", "count"));
  cmd->add_option("--from", args->from, "Perturb this cloud (PLY, LAS, XYZ) instead of a SHAPE")
      ->excludes(shape)
      ->excludes(points);
  cmd->add_option("-o,--output", args->output, "Output file (binary PLY)")->required();
  cmd->add_option("--noise", args->noise,
                  "Gaussian noise sigma per coordinate, as a fraction of the mean spacing "
                  "(SHAPE: sqrt(area / points); --from: mean nearest-neighbour distance)")
      ->capture_default_str()
      ->check(finite_range(0.0, 100.0));
  cmd->add_option("--outliers", args->outliers,
                  "Outliers, as a fraction of the points, uniform in the bounding box")
      ->capture_default_str()
      ->check(finite_range(0.0, 100.0));
  cmd->add_option("--seed", args->seed, "Random seed")
      ->check(unsigned_number())
      ->capture_default_str();
  cmd->callback([args] { run_synth(*args); });
}

}  // namespace g2s::cli
