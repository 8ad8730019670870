// Tangent planes by PCA of a point's nearest neighbours (see tangent_planes.hpp for why).
#include "grow/tangent_planes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>

namespace g2s {

void smallest_eigen(const double m[9], double values[3], Vec3& vector) {
  double a[3][3], v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) a[i][j] = m[3 * i + j];
  }
  for (int sweep = 0; sweep < 32; ++sweep) {
    const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
    if (!(off > 1e-30 * diag)) break;  // also ends on NaN
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        if (a[p][q] == 0) continue;
        // The rotation that zeroes a[p][q] (the smaller of the two angles that do).
        const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        const double t =
            (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // a = a J
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {  // a = J^T a
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {  // v = v J: columns are the eigenvectors
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
    }
  }
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int i, int j) { return a[i][i] < a[j][j]; });
  for (int i = 0; i < 3; ++i) values[i] = a[order[i]][order[i]];
  vector = normalized(Vec3{v[0][order[0]], v[1][order[0]], v[2][order[0]]});
}

TangentPlane fit_tangent_plane(const HashGrid& grid, std::uint32_t centre, int k, double bound_rad,
                               std::vector<std::pair<double, std::uint32_t>>& near) {
  const auto wanted = static_cast<std::size_t>(std::max(k, 3));
  const double spacing = std::max(grid.spacing(), 1e-30);
  const Vec3 c = grid.position(centre);
  // A ball that holds about k points of a surface sampled at the median spacing; doubled where
  // the sampling is sparser.
  double radius = spacing * std::sqrt(static_cast<double>(wanted) / std::numbers::pi);
  for (;; radius *= 2) {
    near.clear();
    grid.for_each_in_ball(c, radius, [&](std::uint32_t j, double d2) { near.push_back({d2, j}); });
    if (near.size() >= wanted || radius >= 8 * spacing) break;
  }
  if (near.size() < 3) return {{0, 0, 0}, 0};
  if (near.size() > wanted) {
    std::nth_element(near.begin(), near.begin() + static_cast<long>(wanted), near.end());
    near.resize(wanted);
  }
  Vec3 mean{0, 0, 0};
  for (const auto& [d2, j] : near) mean = mean + (grid.position(j) - c);
  mean = mean * (1.0 / static_cast<double>(near.size()));
  double cov[9] = {};
  for (const auto& [d2, j] : near) {
    const Vec3 d = grid.position(j) - c - mean;
    const double xyz[3] = {d.x, d.y, d.z};
    for (int r = 0; r < 3; ++r) {
      for (int s = r; s < 3; ++s) cov[3 * r + s] += xyz[r] * xyz[s];
    }
  }
  cov[3] = cov[1], cov[6] = cov[2], cov[7] = cov[5];
  double values[3];
  Vec3 normal;
  smallest_eigen(cov, values, normal);
  if (!(values[1] > 0) || norm2(normal) == 0) return {{0, 0, 0}, 0};
  // How far the fitted normal may be off: the neighbourhood's thickness over its width.
  const double slack = std::atan(std::sqrt(std::max(values[0], 0.0) / values[1]));
  const double limit = bound_rad + slack;
  const float cos_limit =
      limit >= std::numbers::pi / 2 ? 0.0f : static_cast<float>(std::cos(limit));
  const double sigma = std::sqrt(std::max(values[0], 0.0) / static_cast<double>(near.size()));
  const double offset = std::abs(dot(mean, normal));
  static const double thick = std::getenv("G2S_THICK") ? std::atof(std::getenv("G2S_THICK")) : 4.0;
  const float off_middle = thick * sigma > spacing ? static_cast<float>(offset / sigma) : 0.0f;
  return {
      {static_cast<float>(normal.x), static_cast<float>(normal.y), static_cast<float>(normal.z)},
      cos_limit,
      off_middle};
}

}  // namespace g2s
