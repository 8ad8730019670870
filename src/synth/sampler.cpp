// Stratified ("jittered grid") sampling of the synthetic shapes. Uniform random sampling leaves
// clumps and near-duplicates that no real scanner produces, and an interpolating mesher copies
// them into slivers; one jittered point per near-square cell gives the even spacing of a scan.
#include "synth/sampler.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

#include "synth/counter_rng.hpp"
#include "synth/noise.hpp"

namespace g2s::synth {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTorusMajor = 1.0;        // R: centre of the tube to the axis
constexpr double kTorusMinor = 0.35;       // r: tube radius
constexpr double kPlateHalfThick = 0.025;  // the plate is 2 x 2 x 0.05
constexpr double kTerrainBound = 0.06;     // |terrain_height| <= 0.05 + 0.01
// Density of the uneven sphere: proportional to exp(k z), so 16 = exp(2k) from pole to pole.
constexpr double kUnevenK = 1.3862943611198906;  // ln 4

using Vec3 = std::array<double, 3>;

// Splits n points into parts: part j gets [start[j], start[j+1]) with start[j] = round(n * cum[j])
// for the non-decreasing cumulative fractions cum (cum[0] = 0, cum.back() = 1). The total is n
// exactly, and each part's count is within 1 of its exact share.
std::vector<std::uint64_t> split_counts(std::uint64_t n, const std::vector<double>& cum) {
  std::vector<std::uint64_t> start(cum.size());
  for (std::size_t j = 0; j < cum.size(); ++j) {
    const double c = std::clamp(cum[j], 0.0, 1.0);
    start[j] = std::min(n, static_cast<std::uint64_t>(std::llround(static_cast<double>(n) * c)));
  }
  start.front() = 0;
  start.back() = n;
  for (std::size_t j = 1; j < start.size(); ++j) start[j] = std::max(start[j], start[j - 1]);
  return start;
}

// Rows for a patch of n points and the given area, `extent` long across its rows: square cells
// of side sqrt(area / n) need extent / sqrt(area / n) rows (at least 1, at most n).
std::uint64_t row_count(std::uint64_t n, double extent, double area) {
  if (n == 0) return 0;
  const double rows = extent / std::sqrt(area / static_cast<double>(n));
  return std::clamp<std::uint64_t>(static_cast<std::uint64_t>(std::llround(rows)), 1, n);
}

double norm(const Vec3& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

void set_rows(Patch& patch, std::uint64_t n, const std::vector<double>& edges,
              const std::vector<double>& cum) {
  patch.row_edge = edges;
  patch.row_start = split_counts(n, cum);
}

// A flat rectangle (or the xy domain of the height field): rows run along edge_u, stacked along
// edge_v, each with the same share of points.
Patch make_rectangle(Patch::Kind kind, const Vec3& origin, const Vec3& u, const Vec3& v,
                     std::uint64_t n) {
  Patch patch;
  patch.kind = kind;
  patch.origin = origin;
  patch.edge_u = u;
  patch.edge_v = v;
  const double width = norm(u), height = norm(v);
  const std::uint64_t rows = row_count(n, height, width * height);
  std::vector<double> edges(rows + 1);
  for (std::uint64_t j = 0; j <= rows; ++j)
    edges[j] = rows == 0 ? 0.0 : static_cast<double>(j) / static_cast<double>(rows);
  set_rows(patch, n, edges, edges);
  return patch;
}

// The unit sphere with density proportional to exp(k z) (k = 0: uniform). Rows are bands of
// latitude whose height is the local spacing 1 / sqrt(n * density): the row parameter
// q(theta) = integral of sqrt(density) dtheta is tabulated and inverted. Each band gets points in
// proportion to its probability mass, which is analytic in z.
Patch make_sphere(std::uint64_t n, double k) {
  Patch patch;
  patch.kind = Patch::Kind::sphere_rings;
  patch.density_k = k;
  // Normalised density as a function of z, and the mass above z (from the pole z = 1).
  const double total = k == 0.0 ? 2.0 : (std::exp(k) - std::exp(-k)) / k;
  auto density = [&](double z) { return std::exp(k * z) / (2.0 * kPi * total); };
  auto mass_above = [&](double z) {
    return k == 0.0 ? (1.0 - z) / 2.0 : (std::exp(k) - std::exp(k * z)) / (k * total);
  };
  constexpr int kTable = 4096;
  std::vector<double> q(kTable + 1, 0.0);
  for (int i = 1; i <= kTable; ++i) {
    const double a = kPi * (i - 1) / kTable, b = kPi * i / kTable;
    q[i] = q[i - 1] +
           0.5 * (b - a) * (std::sqrt(density(std::cos(a))) + std::sqrt(density(std::cos(b))));
  }
  const std::uint64_t rows =
      n == 0 ? 0
             : std::clamp<std::uint64_t>(static_cast<std::uint64_t>(std::llround(
                                             std::sqrt(static_cast<double>(n)) * q[kTable])),
                                         1, n);
  std::vector<double> edges(rows + 1), cum(rows + 1);
  for (std::uint64_t j = 0; j <= rows; ++j) {
    double z = 1.0;
    if (rows > 0 && j == rows) {
      z = -1.0;
    } else if (j > 0) {
      const double target = q[kTable] * static_cast<double>(j) / static_cast<double>(rows);
      const auto it = std::lower_bound(q.begin(), q.end(), target);
      const auto i = static_cast<int>(std::clamp<std::ptrdiff_t>(it - q.begin(), 1, kTable));
      const double f = (target - q[i - 1]) / (q[i] - q[i - 1]);
      z = std::cos(kPi * (i - 1 + f) / kTable);
    }
    edges[j] = z;
    cum[j] = mass_above(z);
  }
  set_rows(patch, n, edges, cum);
  return patch;
}

// The torus: rows are bands of the tube angle theta (theta = 0 on the outer equator), of equal
// width; a band's area is 2 pi r (R dtheta + r dsin(theta)).
Patch make_torus(std::uint64_t n) {
  Patch patch;
  patch.kind = Patch::Kind::torus_rings;
  const double area = shape_area(SynthShape::torus);
  const std::uint64_t rows = row_count(n, 2.0 * kPi * kTorusMinor, area);
  std::vector<double> edges(rows + 1), cum(rows + 1);
  for (std::uint64_t j = 0; j <= rows; ++j) {
    const double theta =
        rows == 0 ? 0.0 : 2.0 * kPi * static_cast<double>(j) / static_cast<double>(rows);
    edges[j] = theta;
    cum[j] = (kTorusMajor * theta + kTorusMinor * std::sin(theta)) / (2.0 * kPi * kTorusMajor);
  }
  set_rows(patch, n, edges, cum);
  return patch;
}

// The six faces of the box [-a, a] x [-b, b] x [-c, c], edges chosen so edge_u x edge_v points
// outward. The fixed coordinate of a face comes from its origin alone, so points lie exactly on it.
std::vector<Patch> make_box(std::uint64_t n, double a, double b, double c) {
  struct Face {
    Vec3 origin, u, v;
  };
  const Face faces[6] = {
      {{a, -b, -c}, {0, 2 * b, 0}, {0, 0, 2 * c}},   // +x
      {{-a, -b, -c}, {0, 0, 2 * c}, {0, 2 * b, 0}},  // -x
      {{-a, b, -c}, {0, 0, 2 * c}, {2 * a, 0, 0}},   // +y
      {{-a, -b, -c}, {2 * a, 0, 0}, {0, 0, 2 * c}},  // -y
      {{-a, -b, c}, {2 * a, 0, 0}, {0, 2 * b, 0}},   // +z
      {{-a, -b, -c}, {0, 2 * b, 0}, {2 * a, 0, 0}},  // -z
  };
  std::vector<double> cum(7, 0.0);
  double total = 0.0;
  for (int f = 0; f < 6; ++f) {
    total += norm(faces[f].u) * norm(faces[f].v);
    cum[f + 1] = total;
  }
  for (double& x : cum) x /= total;
  const std::vector<std::uint64_t> start = split_counts(n, cum);
  std::vector<Patch> patches;
  patches.reserve(6);
  for (int f = 0; f < 6; ++f)
    patches.push_back(make_rectangle(Patch::Kind::rectangle, faces[f].origin, faces[f].u,
                                     faces[f].v, start[f + 1] - start[f]));
  return patches;
}

double terrain_area() {
  // The integrand sqrt(1 + |grad h|^2) is smooth and 1-periodic in x and y, so the trapezoid
  // rule converges geometrically: 32^2 nodes already give the area to machine precision.
  constexpr int kNodes = 128;
  constexpr double w = 2.0 * kPi;
  double sum = 0.0;
  for (int i = 0; i < kNodes; ++i) {
    const double x = static_cast<double>(i) / kNodes;
    for (int j = 0; j < kNodes; ++j) {
      const double y = static_cast<double>(j) / kNodes;
      const double c = std::cos(w * (2 * x + 3 * y));
      const double hx = 0.05 * w * std::cos(w * x) * std::cos(w * y) + 0.01 * w * 2 * c;
      const double hy = -0.05 * w * std::sin(w * x) * std::sin(w * y) + 0.01 * w * 3 * c;
      sum += std::sqrt(1.0 + hx * hx + hy * hy);
    }
  }
  return sum / (static_cast<double>(kNodes) * kNodes);
}

// Per-row rotation of the rings so their cell boundaries do not line up along one meridian.
double ring_phase(std::size_t row) {
  const double x = static_cast<double>(row) * 0.6180339887498949;
  return x - std::floor(x);
}

void surface_point(const Patch& p, std::size_t row, double s, double t, double out[3]) {
  const double e0 = p.row_edge[row], e1 = p.row_edge[row + 1];
  switch (p.kind) {
    case Patch::Kind::rectangle:
    case Patch::Kind::height_field: {
      const double v = e0 + t * (e1 - e0);
      for (int a = 0; a < 3; ++a) out[a] = p.origin[a] + s * p.edge_u[a] + v * p.edge_v[a];
      if (p.kind == Patch::Kind::height_field) out[2] = terrain_height(out[0], out[1]);
      return;
    }
    case Patch::Kind::sphere_rings: {
      // Inverse of the band's cumulative mass in z: uniform in z (Archimedes) when k = 0.
      const double k = p.density_k;
      double z = k == 0.0 ? e0 + t * (e1 - e0)
                          : std::log((1.0 - t) * std::exp(k * e0) + t * std::exp(k * e1)) / k;
      z = std::clamp(z, -1.0, 1.0);
      const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
      const double phi = 2.0 * kPi * (s + ring_phase(row));
      out[0] = rho * std::cos(phi);
      out[1] = rho * std::sin(phi);
      out[2] = z;
      return;
    }
    case Patch::Kind::torus_rings: {
      // Linear in theta inside the band: the area density varies by O(band width) across it.
      const double theta = e0 + t * (e1 - e0);
      const double phi = 2.0 * kPi * (s + ring_phase(row));
      const double rho = kTorusMajor + kTorusMinor * std::cos(theta);
      out[0] = rho * std::cos(phi);
      out[1] = rho * std::sin(phi);
      out[2] = kTorusMinor * std::sin(theta);
      return;
    }
  }
}

}  // namespace

double terrain_height(double x, double y) {
  constexpr double w = 2.0 * kPi;
  return 0.05 * std::sin(w * x) * std::cos(w * y) + 0.01 * std::sin(w * (2 * x + 3 * y));
}

double shape_area(SynthShape shape) {
  switch (shape) {
    case SynthShape::sphere:
    case SynthShape::uneven:
      return 4.0 * kPi;
    case SynthShape::torus:
      return 4.0 * kPi * kPi * kTorusMajor * kTorusMinor;
    case SynthShape::cube:
      return 24.0;
    case SynthShape::plate:
      return 2.0 * 4.0 + 4.0 * 2.0 * (2.0 * kPlateHalfThick);
    case SynthShape::terrain: {
      static const double area = terrain_area();
      return area;
    }
  }
  return 0.0;
}

Bounds shape_bounds(SynthShape shape) {
  switch (shape) {
    case SynthShape::sphere:
    case SynthShape::uneven:
    case SynthShape::cube:
      return {{-1, -1, -1}, {1, 1, 1}};
    case SynthShape::torus: {
      const double xy = kTorusMajor + kTorusMinor;
      return {{-xy, -xy, -kTorusMinor}, {xy, xy, kTorusMinor}};
    }
    case SynthShape::plate:
      return {{-1, -1, -kPlateHalfThick}, {1, 1, kPlateHalfThick}};
    case SynthShape::terrain:
      return {{0, 0, -kTerrainBound}, {1, 1, kTerrainBound}};
  }
  return {};
}

ShapeSampler::ShapeSampler(const SynthOptions& options)
    : bounds_(shape_bounds(options.shape)), surface_(options.points), seed_(options.seed) {
  const std::uint64_t n = options.points;
  switch (options.shape) {
    case SynthShape::sphere:
      patches_.push_back(make_sphere(n, 0.0));
      break;
    case SynthShape::uneven:
      patches_.push_back(make_sphere(n, kUnevenK));
      break;
    case SynthShape::torus:
      patches_.push_back(make_torus(n));
      break;
    case SynthShape::cube:
      patches_ = make_box(n, 1.0, 1.0, 1.0);
      break;
    case SynthShape::plate:
      patches_ = make_box(n, 1.0, 1.0, kPlateHalfThick);
      break;
    case SynthShape::terrain:
      patches_.push_back(
          make_rectangle(Patch::Kind::height_field, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, n));
      break;
  }
  patch_first_.push_back(0);
  for (Patch& patch : patches_) {
    patch.first = patch_first_.back();
    patch_first_.push_back(patch.first + patch.row_start.back());
  }
  assert(patch_first_.back() == surface_);
  total_ = surface_ + static_cast<std::uint64_t>(
                          std::llround(options.outliers * static_cast<double>(options.points)));
  spacing_ = synth_spacing(options);
  sigma_ = options.noise * spacing_;
}

void ShapeSampler::generate(std::uint64_t begin, std::uint64_t end, float* xyz) const {
  assert(begin <= end && end <= total_);
  std::uint64_t i = begin;
  const std::uint64_t surface_end = std::min(end, surface_);
  if (i < surface_end) {
    // Find the patch and row of the first point, then walk forward.
    std::size_t p = static_cast<std::size_t>(
        std::upper_bound(patch_first_.begin(), patch_first_.end(), i) - patch_first_.begin() - 1);
    const Patch* patch = &patches_[p];
    std::size_t row = static_cast<std::size_t>(
        std::upper_bound(patch->row_start.begin(), patch->row_start.end(), i - patch->first) -
        patch->row_start.begin() - 1);
    for (; i < surface_end; ++i, xyz += 3) {
      while (i >= patch_first_[p + 1]) {
        patch = &patches_[++p];
        row = 0;
      }
      const std::uint64_t local = i - patch->first;
      while (local >= patch->row_start[row + 1]) ++row;
      const std::uint64_t cells = patch->row_start[row + 1] - patch->row_start[row];
      const std::uint64_t cell = local - patch->row_start[row];
      CounterRng rng(seed_, i);
      const double ju = kJitter * (2.0 * rng.uniform() - 1.0);
      const double jv = kJitter * (2.0 * rng.uniform() - 1.0);
      const double s = (static_cast<double>(cell) + 0.5 + ju) / static_cast<double>(cells);
      double point[3] = {0.0, 0.0, 0.0};
      surface_point(*patch, row, s, 0.5 + jv, point);
      if (sigma_ > 0.0) add_gaussian_noise(rng, sigma_, point);
      for (int a = 0; a < 3; ++a) xyz[a] = static_cast<float>(point[a]);
    }
  }
  for (; i < end; ++i, xyz += 3) {
    CounterRng rng(seed_, i);
    double point[3];
    uniform_in_box(rng, bounds_.lo, bounds_.hi, point);
    for (int a = 0; a < 3; ++a) xyz[a] = static_cast<float>(point[a]);
  }
}

}  // namespace g2s::synth
