// Points off the sheet of a thick layer (see off_sheet.hpp for what and why).
#include "grow/off_sheet.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <utility>

namespace g2s {

void symmetric_eigen(const double m[9], double values[3], Vec3 vectors[3]) {
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
        for (int k = 0; k < 3; ++k) {  // v = v J: the columns are the eigenvectors
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
    }
  }
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int i, int j) { return a[i][i] < a[j][j]; });
  for (int k = 0; k < 3; ++k) {
    const int c = order[k];
    values[k] = a[c][c];
    vectors[k] = normalized(Vec3{v[0][c], v[1][c], v[2][c]});
  }
}

namespace {

// Solves the n x n system m x = rhs (m row-major, overwritten) by Gaussian elimination with
// partial pivoting; false when a pivot is below 1e-12 of the largest entry (a neighbourhood too
// degenerate for the fit).
template <int n>
bool solve(double (&m)[n][n], double (&rhs)[n], double (&x)[n]) {
  double scale = 0;
  for (auto& row : m) {
    for (double e : row) scale = std::max(scale, std::abs(e));
  }
  if (!(scale > 0)) return false;
  for (int col = 0; col < n; ++col) {
    int pivot = col;
    for (int r = col + 1; r < n; ++r) {
      if (std::abs(m[r][col]) > std::abs(m[pivot][col])) pivot = r;
    }
    if (!(std::abs(m[pivot][col]) > 1e-12 * scale)) return false;
    std::swap(m[pivot], m[col]);
    std::swap(rhs[pivot], rhs[col]);
    for (int r = col + 1; r < n; ++r) {
      const double f = m[r][col] / m[col][col];
      for (int c = col; c < n; ++c) m[r][c] -= f * m[col][c];
      rhs[r] -= f * rhs[col];
    }
  }
  for (int r = n - 1; r >= 0; --r) {
    double s = rhs[r];
    for (int c = r + 1; c < n; ++c) s -= m[r][c] * x[c];
    x[r] = s / m[r][r];
  }
  return true;
}

// Whether point i lies off the sheet; near is scratch.
bool off_sheet(const HashGrid& grid, std::uint32_t i,
               std::vector<std::pair<double, std::uint32_t>>& near) {
  constexpr auto wanted = static_cast<std::size_t>(kSheetNeighbours);
  constexpr int kTerms = 6;  // h = a u^2 + b uv + c v^2 + d u + e v + f
  const double spacing = grid.spacing();
  if (!(spacing > 0)) return false;
  const Vec3 centre = grid.position(i);
  // A ball that holds about k points of a surface sampled at the median spacing; doubled where
  // the sampling is sparser.
  double radius = spacing * std::sqrt(static_cast<double>(wanted) / std::numbers::pi);
  for (;; radius *= 2) {
    near.clear();
    grid.for_each_in_ball(centre, radius, [&](std::uint32_t j, double d2) {
      near.push_back({d2, j});
    });
    if (near.size() >= wanted || radius >= 8 * spacing) break;
  }
  if (near.size() <= 2 * kTerms) return false;  // too few to tell a spread from the fit
  if (near.size() > wanted) {
    std::nth_element(near.begin(), near.begin() + static_cast<long>(wanted), near.end());
    near.resize(wanted);
  }
  const double count = static_cast<double>(near.size());
  Vec3 mean{0, 0, 0};
  for (const auto& [d2, j] : near) mean = mean + (grid.position(j) - centre);
  mean = mean * (1.0 / count);
  double cov[9] = {};
  for (const auto& [d2, j] : near) {
    const Vec3 d = grid.position(j) - centre - mean;
    const double xyz[3] = {d.x, d.y, d.z};
    for (int r = 0; r < 3; ++r) {
      for (int s = r; s < 3; ++s) cov[3 * r + s] += xyz[r] * xyz[s];
    }
  }
  cov[3] = cov[1], cov[6] = cov[2], cov[7] = cov[5];
  double values[3];
  Vec3 axes[3];
  symmetric_eigen(cov, values, axes);
  // Thin already about the plane: thinner still about the quadric, which contains the plane.
  static const double kThickX =
      std::getenv("G2S_THICK") ? std::atof(std::getenv("G2S_THICK")) : 2.0;
  static const double kKappa = std::getenv("G2S_KAPPA") ? std::atof(std::getenv("G2S_KAPPA")) : 2.0;
  const double thick = spacing / kThickX;  // 4 standard deviations: the layer's width
  if (!(values[0] > thick * thick * count)) return false;
  // The quadric height field over the plane, in units of the neighbourhood's width.
  const double width = std::sqrt(values[2] / count);
  if (!(width > 0)) return false;
  double ata[kTerms][kTerms] = {}, ath[kTerms] = {}, x[kTerms] = {};
  const auto terms_of = [&](const Vec3& d, double(&row)[kTerms], double& h) {
    const double u = dot(d, axes[2]) / width, v = dot(d, axes[1]) / width;
    h = dot(d, axes[0]) / width;
    row[0] = u * u, row[1] = u * v, row[2] = v * v, row[3] = u, row[4] = v, row[5] = 1;
  };
  for (const auto& [d2, j] : near) {
    double row[kTerms], h = 0;
    terms_of(grid.position(j) - centre - mean, row, h);
    for (int r = 0; r < kTerms; ++r) {
      for (int s = 0; s < kTerms; ++s) ata[r][s] += row[r] * row[s];
      ath[r] += row[r] * h;
    }
  }
  if (!solve(ata, ath, x)) return false;
  const auto residual = [&](const Vec3& d) {
    double row[kTerms], h = 0;
    terms_of(d, row, h);
    for (int r = 0; r < kTerms; ++r) h -= x[r] * row[r];
    return h * width;
  };
  double sum2 = 0, most = 0;
  for (const auto& [d2, j] : near) {
    const double r = residual(grid.position(j) - centre - mean);
    sum2 += r * r;
    if (j != i) most = std::max(most, r * r);
  }
  const double variance = sum2 / (count - kTerms);
  if (!(variance > thick * thick)) return false;
  const double own = residual(Vec3{0, 0, 0} - mean);
  static const bool extreme = std::getenv("G2S_EXTREME") != nullptr;
  static const double cap = std::getenv("G2S_CAP") ? std::atof(std::getenv("G2S_CAP")) : 2.0;
  if (extreme && own * own < most) return false;
  if (cap > 0 && own * own > cap * cap * spacing * spacing) return false;
  return own * own > kKappa * kKappa * variance;  // beyond two standard deviations
}

}  // namespace

std::vector<std::uint8_t> off_sheet_points(const HashGrid& grid) {
  std::vector<std::uint8_t> off(grid.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, grid.size(), 4096),
                    [&](const tbb::blocked_range<std::uint32_t>& range) {
                      std::vector<std::pair<double, std::uint32_t>> near;
                      for (std::uint32_t i = range.begin(); i < range.end(); ++i) {
                        off[i] = off_sheet(grid, i, near);
                      }
                    });
  return off;
}

}  // namespace g2s
