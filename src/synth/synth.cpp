// The public synthetic-cloud API (include/g2s/synth.hpp): option checks, the in-memory cloud and
// the streamed PLY writer. Both draw from synth::ShapeSampler, which generates any range of
// points independently, so chunks are filled in parallel and the output never depends on them.
#include "g2s/synth.hpp"

#include <fmt/core.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <array>
#include <cmath>
#include <vector>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "synth/noise.hpp"
#include "synth/sampler.hpp"

namespace g2s {
namespace {

constexpr std::array<std::pair<SynthShape, std::string_view>, 6> kNames{{
    {SynthShape::sphere, "sphere"},
    {SynthShape::torus, "torus"},
    {SynthShape::cube, "cube"},
    {SynthShape::plate, "plate"},
    {SynthShape::uneven, "uneven"},
    {SynthShape::terrain, "terrain"},
}};

// Far beyond any real use, and small enough that counts stay exact in double arithmetic.
constexpr std::uint64_t kMaxPoints = std::uint64_t{1} << 40;

void check_options(const SynthOptions& options) {
  if (options.points == 0 || options.points > kMaxPoints)
    throw Error(Exit::usage, fmt::format("synthetic cloud: points must be in 1..{}, not {}",
                                         kMaxPoints, options.points));
  synth::check_noise_and_outliers("synthetic cloud", options.noise, options.outliers);
}

// Fills xyz (3 floats per point) with points [begin, end) on all cores.
void generate_parallel(const synth::ShapeSampler& sampler, std::uint64_t begin, std::uint64_t end,
                       float* xyz) {
  tbb::parallel_for(tbb::blocked_range<std::uint64_t>(begin, end, 16384),
                    [&](const tbb::blocked_range<std::uint64_t>& range) {
                      sampler.generate(range.begin(), range.end(),
                                       xyz + 3 * (range.begin() - begin));
                    });
}

}  // namespace

std::optional<SynthShape> synth_shape_from_name(std::string_view name) {
  for (const auto& [shape, shape_name] : kNames)
    if (shape_name == name) return shape;
  return std::nullopt;
}

std::string_view synth_shape_name(SynthShape shape) {
  for (const auto& [known, shape_name] : kNames)
    if (known == shape) return shape_name;
  return "unknown";
}

double synth_spacing(const SynthOptions& options) {
  return std::sqrt(synth::shape_area(options.shape) / static_cast<double>(options.points));
}

PointCloud make_synthetic_cloud(const SynthOptions& options) {
  check_options(options);
  const synth::ShapeSampler sampler(options);
  const std::uint64_t total = sampler.total_points();
  PointCloud cloud;
  cloud.xyz.resize(3 * total);
  tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, total, 16384),
                    [&](const tbb::blocked_range<std::uint64_t>& range) {
                      constexpr std::uint64_t kBatch = 4096;
                      std::array<float, 3 * kBatch> batch;
                      for (std::uint64_t b = range.begin(); b < range.end(); b += kBatch) {
                        const std::uint64_t e = std::min(range.end(), b + kBatch);
                        sampler.generate(b, e, batch.data());
                        for (std::uint64_t k = 0; k < 3 * (e - b); ++k)
                          cloud.xyz[3 * b + k] = static_cast<double>(batch[k]);
                      }
                    });
  return cloud;
}

void write_synthetic_cloud(const std::filesystem::path& target, const SynthOptions& options) {
  check_options(options);
  const synth::ShapeSampler sampler(options);
  const std::uint64_t total = sampler.total_points();
  PlyPointWriter writer(target, total);
  // Two chunk buffers: the next chunk is generated (on the other cores) while this one is
  // written. Memory: 2 x 12 MiB whatever the point count.
  constexpr std::uint64_t kChunk = std::uint64_t{1} << 20;
  std::array<std::vector<float>, 2> buffers{std::vector<float>(3 * std::min(total, kChunk)),
                                            std::vector<float>(3 * std::min(total, kChunk))};
  tbb::task_group next;
  generate_parallel(sampler, 0, std::min(total, kChunk), buffers[0].data());
  for (std::uint64_t begin = 0, chunk = 0; begin < total; begin += kChunk, ++chunk) {
    const std::uint64_t end = std::min(total, begin + kChunk);
    if (end < total) {
      next.run([&, end, chunk] {
        generate_parallel(sampler, end, std::min(total, end + kChunk),
                          buffers[(chunk + 1) % 2].data());
      });
    }
    try {
      const float* xyz = buffers[chunk % 2].data();
      for (std::uint64_t k = 0; k < end - begin; ++k)
        writer.add(xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]);
    } catch (...) {
      next.cancel();  // the generator reads `buffers`: let it stop before they go
      next.wait();
      throw;
    }
    next.wait();
  }
  writer.finish();
}

}  // namespace g2s
