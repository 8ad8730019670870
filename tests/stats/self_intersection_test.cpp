// Tests of the exact predicates (against integer arithmetic on random and nearly degenerate
// inputs), of the triangle-pair crossing test (hand-made pairs with known answers) and of the
// crossing counts of compute_stats (hand-made meshes; a random soup against all pairs).
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "common/exact_predicates.hpp"
#include "common/triangle_intersection.hpp"
#include "g2s/stats.hpp"

namespace {

using g2s::Index;
using g2s::IndexedMesh;
using g2s::Triangle;
using g2s::Vec3;
using Corners = std::array<Vec3, 3>;

// ---- Exact references on integer-valued doubles ----

__extension__ typedef __int128 Int128;  // a GCC/Clang extension, fine in a test

int sign(Int128 v) {
  return v > 0 ? 1 : (v < 0 ? -1 : 0);
}

// Integer-valued doubles of up to 53 significant bits times 2^0..2^7 (below 2^61), so that
// differences of two of them are not always doubles: the exact path has to carry their tails.
double random_integer(std::mt19937_64& rng) {
  const auto mantissa = static_cast<std::int64_t>(rng() >> 11);  // 53 bits
  const int shift = static_cast<int>(rng() % 8);
  const double magnitude = std::ldexp(static_cast<double>(mantissa >> (rng() % 50)), shift);
  return (rng() & 1) ? magnitude : -magnitude;
}

Int128 to_int(double d) {
  return static_cast<Int128>(d);
}

// Sign of (b-a) x (c-a) in the plane (0, 1): differences below 2^62, products below 2^124.
int orient2d_reference(const double* a, const double* b, const double* c) {
  const Int128 ux = to_int(b[0]) - to_int(a[0]), uy = to_int(b[1]) - to_int(a[1]);
  const Int128 vx = to_int(c[0]) - to_int(a[0]), vy = to_int(c[1]) - to_int(a[1]);
  return sign(ux * vy - uy * vx);
}

// A signed 256-bit accumulator of products of three integers below 2^62: enough for a 3x3
// determinant of such differences (six terms below 2^186).
struct Int256 {
  std::uint64_t limb[4] = {0, 0, 0, 0};  // two's complement, little-endian

  void add_product(Int128 x, Int128 y, Int128 z) {
    const bool negative = ((x < 0) != (y < 0)) != (z < 0);
    __extension__ typedef unsigned __int128 U128;
    const U128 xy = static_cast<U128>(x < 0 ? -x : x) * static_cast<U128>(y < 0 ? -y : y);
    const auto zz = static_cast<std::uint64_t>(z < 0 ? -z : z);
    const U128 low = static_cast<U128>(static_cast<std::uint64_t>(xy)) * zz;
    const U128 high = static_cast<U128>(static_cast<std::uint64_t>(xy >> 64)) * zz;
    std::uint64_t p[4];
    p[0] = static_cast<std::uint64_t>(low);
    const U128 middle = (low >> 64) + static_cast<std::uint64_t>(high);
    p[1] = static_cast<std::uint64_t>(middle);
    p[2] = static_cast<std::uint64_t>((middle >> 64) + (high >> 64));
    p[3] = 0;
    if (negative) {  // two's complement of p
      unsigned carry = 1;
      for (auto& w : p) {
        w = ~w + carry;
        carry = carry && w == 0;
      }
    }
    unsigned carry = 0;
    for (int i = 0; i < 4; ++i) {
      const U128 sum = static_cast<U128>(limb[i]) + p[i] + carry;
      limb[i] = static_cast<std::uint64_t>(sum);
      carry = static_cast<unsigned>(sum >> 64);
    }
  }
  int sign() const {
    if (limb[3] >> 63) return -1;
    return (limb[0] | limb[1] | limb[2] | limb[3]) != 0 ? 1 : 0;
  }
};

// Sign of det[b-a, c-a, d-a].
int orient3d_reference(const double* a, const double* b, const double* c, const double* d) {
  Int128 u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = to_int(b[k]) - to_int(a[k]);
    v[k] = to_int(c[k]) - to_int(a[k]);
    w[k] = to_int(d[k]) - to_int(a[k]);
  }
  Int256 det;
  for (int k = 0; k < 3; ++k) {
    const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
    det.add_product(w[k], u[k1], v[k2]);
    det.add_product(-w[k], u[k2], v[k1]);
  }
  return det.sign();
}

TEST(ExactPredicates, Orient2dMatchesIntegersOnRandomAndNearlyCollinearPoints) {
  std::mt19937_64 rng(7);
  int exact_zero = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    double a[3], b[3], c[3];
    for (int k = 0; k < 2; ++k) {
      a[k] = random_integer(rng);
      b[k] = random_integer(rng);
    }
    a[2] = b[2] = c[2] = 0;
    if (trial % 4 == 0) {
      for (int k = 0; k < 2; ++k) c[k] = random_integer(rng);
    } else if (trial % 4 == 1) {  // small: on the line a + m (b - a), nudged
      const double m = static_cast<double>(rng() % 7) - 3.0;
      for (int k = 0; k < 2; ++k) {
        a[k] = std::fmod(a[k], 1024.0), b[k] = std::fmod(b[k], 1024.0);
        c[k] = a[k] + m * (b[k] - a[k]) + static_cast<double>(rng() % 3) - 1.0;
      }
    } else {  // on the line through a and b, rounded to an integer, then nudged by -1, 0 or 1
      const double t = std::ldexp(static_cast<double>(rng() % 4096), -10) - 1.0;
      for (int k = 0; k < 2; ++k) {
        c[k] = std::nearbyint(a[k] + t * (b[k] - a[k])) + static_cast<double>(rng() % 3) - 1.0;
        if (std::fabs(c[k]) >= 0x1p61) c[k] = 0;
      }
    }
    const int expected = orient2d_reference(a, b, c);
    exact_zero += expected == 0;
    ASSERT_EQ(g2s::exact::orient2d(a, b, c, 0, 1), expected)
        << a[0] << " " << a[1] << " / " << b[0] << " " << b[1] << " / " << c[0] << " " << c[1];
    ASSERT_EQ(g2s::exact::orient2d(b, c, a, 0, 1), expected);
    ASSERT_EQ(g2s::exact::orient2d(b, a, c, 0, 1), -expected);
    const double as[3] = {std::ldexp(a[0], 40), std::ldexp(a[1], 40), 0};
    const double bs[3] = {std::ldexp(b[0], 40), std::ldexp(b[1], 40), 0};
    const double cs[3] = {std::ldexp(c[0], 40), std::ldexp(c[1], 40), 0};
    ASSERT_EQ(g2s::exact::orient2d(as, bs, cs, 0, 1), expected);
  }
  EXPECT_GT(exact_zero, 1000);  // the nearly collinear half really reaches zero
}

TEST(ExactPredicates, Orient3dMatchesIntegersOnRandomAndNearlyCoplanarPoints) {
  std::mt19937_64 rng(11);
  int exact_zero = 0;
  for (int trial = 0; trial < 100000; ++trial) {
    double a[3], b[3], c[3], d[3];
    for (int k = 0; k < 3; ++k) {
      a[k] = random_integer(rng);
      b[k] = random_integer(rng);
      c[k] = random_integer(rng);
    }
    if (trial % 2 == 0) {
      for (int k = 0; k < 3; ++k) d[k] = random_integer(rng);
    } else {  // in the plane of a, b, c, rounded to integers and nudged
      const double s = std::ldexp(static_cast<double>(rng() % 1024), -9) - 0.5;
      const double t = std::ldexp(static_cast<double>(rng() % 1024), -9) - 0.5;
      for (int k = 0; k < 3; ++k) {
        d[k] = std::nearbyint(a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k])) +
               static_cast<double>(rng() % 3) - 1.0;
        if (std::fabs(d[k]) >= 0x1p61) d[k] = 0;
      }
      if (trial % 4 == 1) {  // small coordinates: the nudge decides the sign, often zero
        for (int k = 0; k < 3; ++k) {
          a[k] = std::fmod(a[k], 1024.0), b[k] = std::fmod(b[k], 1024.0);
          c[k] = std::fmod(c[k], 1024.0);
        }
        const double m = static_cast<double>(rng() % 5) - 2.0,
                     n = static_cast<double>(rng() % 5) - 2.0;
        for (int k = 0; k < 3; ++k) {
          d[k] =
              a[k] + m * (b[k] - a[k]) + n * (c[k] - a[k]) + static_cast<double>(rng() % 3) - 1.0;
        }
      }
    }
    const int expected = orient3d_reference(a, b, c, d);
    exact_zero += expected == 0;
    ASSERT_EQ(g2s::exact::orient3d(a, b, c, d), expected) << trial;
    ASSERT_EQ(g2s::exact::orient3d(b, c, a, d), expected) << trial;
    ASSERT_EQ(g2s::exact::orient3d(b, a, c, d), -expected) << trial;
    ASSERT_EQ(g2s::exact::orient3d(d, b, c, a), -expected) << trial;
    // Scaled by a power of two (exactly): the same sign, whichever of the integer fast path or
    // the expansions decides it.
    double as[3], bs[3], cs[3], ds[3];
    for (int k = 0; k < 3; ++k) {
      as[k] = std::ldexp(a[k], -70), bs[k] = std::ldexp(b[k], -70);
      cs[k] = std::ldexp(c[k], -70), ds[k] = std::ldexp(d[k], -70);
    }
    ASSERT_EQ(g2s::exact::orient3d(as, bs, cs, ds), expected) << trial;
  }
  EXPECT_GT(exact_zero, 300);
}

TEST(ExactPredicates, TinyOffsetsFromLargeCoordinates) {
  // A point 1 ulp off the plane z = 1e7 through three far-apart points: plain double evaluation
  // of the determinant loses it, the exact one does not.
  const double z = 1e7;
  const double a[3] = {0.1, 0.2, z}, b[3] = {1e5 + 0.3, 0.7, z}, c[3] = {0.9, 1e5 - 0.1, z};
  const double above[3] = {3.3, 4.4, std::nextafter(z, 2 * z)};
  const double below[3] = {3.3, 4.4, std::nextafter(z, 0.0)};
  const double on[3] = {3.3, 4.4, z};
  EXPECT_EQ(g2s::exact::orient3d(a, b, c, above), 1);
  EXPECT_EQ(g2s::exact::orient3d(a, b, c, below), -1);
  EXPECT_EQ(g2s::exact::orient3d(a, b, c, on), 0);
  EXPECT_TRUE(g2s::exact::collinear(a, a, b));
  // Zero differences (repeated points, shared coordinates) on the integer path and beside it.
  EXPECT_EQ(g2s::exact::orient3d(on, on, on, on), 0);
  const double o[3] = {0, 0, 0}, x[3] = {1, 0, 0}, y[3] = {0, 1, 0}, half[3] = {0, 0, 0.5};
  const double tiny[3] = {0, 0, 1e-300};
  EXPECT_EQ(g2s::exact::orient3d(o, x, y, half), -g2s::exact::orient3d(o, y, x, half));
  EXPECT_NE(g2s::exact::orient3d(o, x, y, half), 0);
  EXPECT_EQ(g2s::exact::orient3d(o, x, y, tiny), g2s::exact::orient3d(o, x, y, half));
  EXPECT_EQ(g2s::exact::orient2d(o, o, o, 0, 1), 0);
  const double m[3] = {0.5, 0.5, 0.5}, n[3] = {1.5, 1.5, 1.5}, p[3] = {2.5, 2.5, 2.5};
  EXPECT_TRUE(g2s::exact::collinear(m, n, p));
  const double q[3] = {2.5, 2.5, std::nextafter(2.5, 3.0)};
  EXPECT_FALSE(g2s::exact::collinear(m, n, q));
}

// ---- The crossing test on hand-made pairs ----

bool cross(const Corners& a, const Corners& b) {
  return g2s::triangles_cross(a.data(), b.data());
}

// The answer must not depend on the order of the pair, the corners' rotation or orientation.
void expect_cross(const Corners& a, const Corners& b, bool expected) {
  for (int rotate = 0; rotate < 3; ++rotate) {
    Corners ra = {a[rotate], a[(rotate + 1) % 3], a[(rotate + 2) % 3]};
    Corners rb = {b[(rotate + 1) % 3], b[rotate], b[(rotate + 2) % 3]};  // flipped
    EXPECT_EQ(cross(ra, rb), expected) << "rotation " << rotate;
    EXPECT_EQ(cross(rb, ra), expected) << "rotation " << rotate << ", swapped";
  }
  const g2s::Vec3f af[3] = {{float(a[0].x), float(a[0].y), float(a[0].z)},
                            {float(a[1].x), float(a[1].y), float(a[1].z)},
                            {float(a[2].x), float(a[2].y), float(a[2].z)}};
  const g2s::Vec3f bf[3] = {{float(b[0].x), float(b[0].y), float(b[0].z)},
                            {float(b[1].x), float(b[1].y), float(b[1].z)},
                            {float(b[2].x), float(b[2].y), float(b[2].z)}};
  bool exactly_float = true;
  for (int k = 0; k < 3; ++k) {
    exactly_float = exactly_float && Vec3(af[k]).x == a[k].x && Vec3(af[k]).y == a[k].y &&
                    Vec3(af[k]).z == a[k].z && Vec3(bf[k]).x == b[k].x && Vec3(bf[k]).y == b[k].y &&
                    Vec3(bf[k]).z == b[k].z;
  }
  if (exactly_float) {
    EXPECT_EQ(g2s::triangles_cross(af, bf), expected) << "float";
  }
}

bool degenerate(const Corners& t) {
  const double a[3] = {t[0].x, t[0].y, t[0].z}, b[3] = {t[1].x, t[1].y, t[1].z},
               c[3] = {t[2].x, t[2].y, t[2].z};
  return g2s::exact::collinear(a, b, c);
}

const Corners kFloor = {Vec3{0, 0, 0}, Vec3{4, 0, 0}, Vec3{0, 4, 0}};  // in z = 0

TEST(TrianglesCross, PiercingTriangles) {
  expect_cross(kFloor, {Vec3{1, 1, -1}, Vec3{1, 1, 1}, Vec3{2, 1, 1}}, true);
}

TEST(TrianglesCross, ApartAndNearMisses) {
  expect_cross(kFloor, {Vec3{1, 1, 1}, Vec3{2, 1, 1}, Vec3{1, 2, 3}}, false);
  // A corner 1e-7 above the floor, and the same corner exactly on it.
  expect_cross(kFloor, {Vec3{1, 1, 1e-7}, Vec3{2, 1, 1}, Vec3{1, 2, 1}}, false);
  expect_cross(kFloor, {Vec3{1, 1, 0}, Vec3{2, 1, 1}, Vec3{1, 2, 1}}, true);
  // Crossing the floor's plane 1e-7 beyond its hypotenuse x + y = 4, and 1e-7 inside it.
  const double e = 1e-7;
  expect_cross(kFloor, {Vec3{2 + e, 2 + e, -1}, Vec3{2 + e, 2 + e, 1}, Vec3{5, 5, 0.5}}, false);
  expect_cross(kFloor, {Vec3{2 - e, 2 - e, -1}, Vec3{2 - e, 2 - e, 1}, Vec3{5, 5, 0.5}}, true);
  // A corner on the floor's edge exactly, and 1e-7 outside it.
  expect_cross(kFloor, {Vec3{2, 0, 0}, Vec3{2, -1, 1}, Vec3{3, -1, 1}}, true);
  expect_cross(kFloor, {Vec3{2, -e, 0}, Vec3{2, -1, 1}, Vec3{3, -1, 1}}, false);
}

TEST(TrianglesCross, TouchingAtAPointCounts) {
  // A corner of one touches the other's interior: the closed triangles meet, no shared corner.
  expect_cross(kFloor, {Vec3{1, 1, 0}, Vec3{1, 1, 2}, Vec3{2, 1, 2}}, true);
  // Corner on corner at different indices is a shared corner: nothing else in common.
  expect_cross(kFloor, {Vec3{0, 0, 0}, Vec3{-1, 0, 2}, Vec3{0, -1, 2}}, false);
}

TEST(TrianglesCross, SharedEdge) {
  // Folded flat onto each other (the fourth corner on the same side of the edge, in the plane).
  expect_cross(kFloor, {Vec3{4, 0, 0}, Vec3{0, 4, 0}, Vec3{1, 1, 0}}, true);
  // Coplanar, on the other side: an ordinary flat pair.
  expect_cross(kFloor, {Vec3{4, 0, 0}, Vec3{0, 4, 0}, Vec3{4, 4, 0}}, false);
  // Folded nearly flat but 1e-7 out of the plane: they meet only in the edge.
  expect_cross(kFloor, {Vec3{4, 0, 0}, Vec3{0, 4, 0}, Vec3{1, 1, 1e-7}}, false);
  // A sharp dihedral.
  expect_cross(kFloor, {Vec3{4, 0, 0}, Vec3{0, 4, 0}, Vec3{1, 1, 1}}, false);
}

TEST(TrianglesCross, CoplanarWithoutSharedCorner) {
  expect_cross(kFloor, {Vec3{1, 1, 0}, Vec3{5, 1, 0}, Vec3{1, 5, 0}}, true);      // overlap
  expect_cross(kFloor, {Vec3{1, 1, 0}, Vec3{1.5, 1, 0}, Vec3{1, 1.5, 0}}, true);  // inside
  expect_cross(kFloor, {Vec3{3, 3, 0}, Vec3{6, 3, 0}, Vec3{3, 6, 0}}, false);     // apart
  expect_cross(kFloor, {Vec3{2, 2, 0}, Vec3{6, 3, 0}, Vec3{3, 6, 0}}, true);      // touching
  // Edges along one line, overlapping or not.
  expect_cross(kFloor, {Vec3{3, 0, 0}, Vec3{6, 0, 0}, Vec3{5, -1, 0}}, true);
  expect_cross(kFloor, {Vec3{5, 0, 0}, Vec3{6, 0, 0}, Vec3{5, -1, 0}}, false);
}

TEST(TrianglesCross, SharedCorner) {
  // Only the corner in common.
  expect_cross(kFloor, {Vec3{0, 0, 0}, Vec3{-1, -1, 1}, Vec3{-2, 1, 1}}, false);
  expect_cross(kFloor, {Vec3{0, 0, 0}, Vec3{-4, 0, 0}, Vec3{0, -4, 0}}, false);  // coplanar
  // The shared corner plus a real crossing elsewhere: the other's far edge pierces the floor.
  expect_cross(kFloor, {Vec3{0, 0, 0}, Vec3{2, 1, -1}, Vec3{1, 2, 1}}, true);
  // Coplanar wedges overlapping at the corner.
  expect_cross(kFloor, {Vec3{0, 0, 0}, Vec3{1, 1, 0}, Vec3{-1, 1, 0}}, true);
  // Along an edge of the floor from the shared corner (a fold about half an edge).
  expect_cross(kFloor, {Vec3{0, 0, 0}, Vec3{2, 0, 0}, Vec3{1, 0, 1}}, true);
  // A near miss: the other triangle's edge passes 1e-7 below the floor's corner (4, 0, 0)...
  expect_cross(kFloor, {Vec3{0, 0, 0}, Vec3{4, 0, -1e-7}, Vec3{4, -1, 1}}, false);
  // ...and through it.
  expect_cross(kFloor, {Vec3{0, 0, 0}, Vec3{5, 0, 0}, Vec3{4, -1, 1}}, true);
}

TEST(TrianglesCross, SameTriangleTwice) {
  expect_cross(kFloor, kFloor, true);
}

TEST(TrianglesCross, SymmetricOnRandomSmallIntegerTriangles) {
  // Small integer corners make every kind of contact common: shared corners, corners on edges,
  // coplanar pairs. The answer must not depend on the order of the pair or of the corners.
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> coordinate(0, 3);
  int crossing = 0, tested = 0;
  for (int trial = 0; trial < 40000; ++trial) {
    Corners t[2];
    for (auto& tri : t) {
      do {
        for (auto& v : tri) v = Vec3(coordinate(rng), coordinate(rng), coordinate(rng) / 2);
      } while (degenerate(tri));
    }
    const bool expected = cross(t[0], t[1]);
    crossing += expected;
    ++tested;
    for (int rotate = 0; rotate < 3; ++rotate) {
      const Corners a = {t[0][rotate], t[0][(rotate + 1) % 3], t[0][(rotate + 2) % 3]};
      const Corners b = {t[1][(rotate + 2) % 3], t[1][(rotate + 1) % 3], t[1][rotate]};
      ASSERT_EQ(cross(a, b), expected) << trial;
      ASSERT_EQ(cross(b, a), expected) << trial;
    }
  }
  EXPECT_GT(crossing, tested / 10);
  EXPECT_LT(crossing, tested);
}

TEST(TrianglesCross, StraddlingPairsAgreeWithTheirSegmentsOnTheCommonLine) {
  // Pairs where each triangle has one corner on one side of the other's plane and two on the
  // other (the test's interval path): each meets the other's plane in a segment of the planes'
  // common line, and they cross exactly when the segments overlap. The segments are computed
  // here in floating point and only clear cases (gaps and margins over 1e-9) are compared.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-1, 1);
  int crossing = 0, apart = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    Corners t[2];
    for (auto& tri : t) {
      for (auto& v : tri) v = Vec3(coordinate(rng), coordinate(rng), coordinate(rng));
    }
    const Vec3 n[2] = {g2s::cross(t[0][1] - t[0][0], t[0][2] - t[0][0]),
                       g2s::cross(t[1][1] - t[1][0], t[1][2] - t[1][0])};
    const Vec3 line = g2s::cross(n[0], n[1]);
    if (norm(n[0]) < 1e-3 || norm(n[1]) < 1e-3 || norm(line) < 1e-3) continue;
    double lo[2], hi[2];
    bool clear = true;
    for (int s = 0; s < 2 && clear; ++s) {
      const Corners& own = t[s];
      const Vec3& other_normal = n[1 - s];
      const Vec3& other_corner = t[1 - s][0];
      double height[3];
      int above = 0;
      for (int k = 0; k < 3; ++k) {
        height[k] = dot(own[k] - other_corner, other_normal) / norm(other_normal);
        clear = clear && std::abs(height[k]) > 1e-9;
        above += height[k] > 0;
      }
      clear = clear && above != 0 && above != 3;
      lo[s] = std::numeric_limits<double>::infinity();
      hi[s] = -lo[s];
      for (int k = 0; k < 3 && clear; ++k) {
        const int l = (k + 1) % 3;
        if ((height[k] > 0) == (height[l] > 0)) continue;
        const Vec3 cut = own[k] + (own[l] - own[k]) * (height[k] / (height[k] - height[l]));
        lo[s] = std::min(lo[s], dot(cut, line));
        hi[s] = std::max(hi[s], dot(cut, line));
      }
    }
    if (!clear) continue;
    const double gap = std::max(lo[0], lo[1]) - std::min(hi[0], hi[1]);
    if (std::abs(gap) < 1e-9) continue;
    const bool expected = gap < 0;
    (expected ? crossing : apart) += 1;
    ASSERT_EQ(cross(t[0], t[1]), expected) << trial;
    ASSERT_EQ(cross(t[1], t[0]), expected) << trial;
    ASSERT_EQ(cross(t[0], {t[1][0], t[1][2], t[1][1]}), expected) << trial;
  }
  EXPECT_GT(crossing, 1000);
  EXPECT_GT(apart, 1000);
}

// ---- Counts of compute_stats ----

IndexedMesh mesh_of(const std::vector<Vec3>& vertices, const std::vector<Triangle>& triangles) {
  IndexedMesh mesh;
  for (const Vec3& v : vertices) mesh.xyz.insert(mesh.xyz.end(), {v.x, v.y, v.z});
  mesh.triangles = triangles;
  return mesh;
}

TEST(StatsCrossings, HandMadeMeshes) {
  // A flat square of two triangles, pierced by a triangle through both halves' shared diagonal,
  // plus a triangle folded flat onto the first half along its edge 0-1.
  const IndexedMesh mesh = mesh_of(
      {{0, 0, 0}, {4, 0, 0}, {4, 4, 0}, {0, 4, 0}, {2, 2, -1}, {2, 2, 1}, {3, 1, 1}, {2, 1, 0}},
      {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {0, 1, 7}});
  const g2s::MeshStats s = g2s::compute_stats(mesh);
  // 4-5-6 crosses both halves (its edge 4-5 passes through the diagonal's midpoint); 0-1-7 lies
  // in 0-1-2 (sharing edge 0-1) and touches 0-2-3 only at the shared corner 0.
  EXPECT_EQ(s.crossing_pairs, 3u);
  EXPECT_EQ(s.crossing_pairs_no_shared_vertex, 2u);
  EXPECT_EQ(s.crossing_triangles, 4u);
}

// Coordinates of extreme magnitude (subnormal, or huge) make the exact predicates' products
// underflow or overflow; each such axis is scaled by a power of two first, which changes no
// answer. Two triangles touching only at a corner, with x subnormal (a flat scan's x scaled by
// 1e-321), were counted as crossing; the hand-made crossings keep their counts at any scale.
TEST(StatsCrossings, ExtremeCoordinatesGiveTheSameAnswers) {
  const IndexedMesh touching = mesh_of({{4.65e-321, -1.2248693704605103, 0.16210317611694336},
                                        {-2.515e-321, -1.316306233406067, 0.08252300322055817},
                                        {2.76e-321, -1.3126708269119263, 0.07718372344970703},
                                        {-1.05e-321, -1.34033203125, 0.06213152036070824},
                                        {2.77e-322, -1.343184232711792, 0.0672852098941803}},
                                       {{1, 3, 4}, {2, 1, 0}});
  EXPECT_EQ(g2s::compute_stats(touching).crossing_pairs, 0u);
  EXPECT_EQ(g2s::compute_stats(touching).degenerate_triangles, 0u);
  const std::vector<Vec3> corners = {{0, 0, 0},  {4, 0, 0}, {4, 4, 0}, {0, 4, 0},
                                     {2, 2, -1}, {2, 2, 1}, {3, 1, 1}, {2, 1, 0}};
  for (const Vec3 scale :
       {Vec3{1e-310, 1, 1}, Vec3{1e-200, 1e-200, 1e-200}, Vec3{1e-300, 1e-300, 1e-300},
        Vec3{1, 1e200, 1}, Vec3{1e250, 1e-250, 1e150}}) {
    std::vector<Vec3> scaled;
    for (const Vec3& c : corners) scaled.push_back({c.x * scale.x, c.y * scale.y, c.z * scale.z});
    const g2s::MeshStats s =
        g2s::compute_stats(mesh_of(scaled, {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {0, 1, 7}}));
    EXPECT_EQ(s.crossing_pairs, 3u) << scale.x << " " << scale.y << " " << scale.z;
    EXPECT_EQ(s.crossing_pairs_no_shared_vertex, 2u);
    EXPECT_EQ(s.degenerate_triangles, 0u) << scale.x << " " << scale.y << " " << scale.z;
  }
}

// A triangle with a NaN corner has no shape and crosses nothing, whichever corner it is (the
// box of a NaN not first among the corners came out finite, and the exact test said 2 pairs).
TEST(StatsCrossings, TrianglesWithANanCornerAreLeftOut) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Triangle& with_nan : {Triangle{0, 1, 2}, Triangle{2, 0, 1}, Triangle{1, 2, 0}}) {
    const IndexedMesh mesh = mesh_of({{0, 0, 0}, {1, 0, 0}, {nan, 1, 0}, {0, 1, 0}, {1, 1, 0}},
                                     {with_nan, {1, 0, 3}, {1, 4, 3}});
    EXPECT_EQ(g2s::compute_stats(mesh).crossing_pairs, 0u);
  }
}

TEST(StatsCrossings, CleanClosedMeshHasNone) {
  // An octahedron: every pair shares an edge or a corner, none crosses.
  const IndexedMesh mesh = mesh_of(
      {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
      {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}});
  const g2s::MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.crossing_pairs, 0u);
  EXPECT_EQ(s.crossing_triangles, 0u);
}

TEST(StatsCrossings, DuplicatesAndDegenerateTrianglesAreLeftOut) {
  const IndexedMesh mesh =
      mesh_of({{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {1, 1, -1}, {1, 1, 1}, {2, 2, 0}},
              {{0, 1, 2}, {2, 1, 0}, {0, 5, 5}, {0, 5, 2}, {3, 4, 5}});
  // {2, 1, 0} duplicates {0, 1, 2}; {0, 5, 5} is degenerate.
  const g2s::MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.duplicate_triangles, 1u);
  EXPECT_EQ(s.degenerate_triangles, 1u);
  // 3-4-5 pierces 0-1-2 at (1, 1, 0); 0-5-2 lies in 0-1-2's plane on its side of the shared
  // edge 0-2 (folded flat), and 3-4-5 shares corner 5 with 0-5-2 and passes through (1,1,0),
  // which lies in 0-5-2 (on its edge 0-5).
  EXPECT_EQ(s.crossing_pairs, 3u);
  EXPECT_EQ(s.crossing_pairs_no_shared_vertex, 1u);
  EXPECT_EQ(s.crossing_triangles, 3u);
}

// Coordinates beyond float's range (the grid's boxes are float) are still compared, exactly.
TEST(StatsCrossings, CoordinatesBeyondFloatRange) {
  const double big = 1e39;
  const IndexedMesh mesh = mesh_of({{0, 0, 0},
                                    {4 * big, 0, 0},
                                    {0, 4 * big, 0},
                                    {big, big, -big},
                                    {big, big, big},
                                    {2 * big, big, big},
                                    {10, 10, 10},
                                    {11, 10, 10},
                                    {10, 11, 10}},
                                   {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}});
  const g2s::MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.crossing_pairs, 1u);
  EXPECT_EQ(s.crossing_triangles, 2u);
}

// A soup of random small triangles in a box, some big, some along one line: the grid's counts
// must equal those of testing every pair.
// 1,500 random triangles in a 10 x 10 x 2 box, many crossing, corners snapped to a 1/8 grid so
// that corners coincide and contacts are exact.
IndexedMesh crossing_soup() {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> position(0.0, 10.0), offset(-0.6, 0.6);
  IndexedMesh mesh;
  for (int t = 0; t < 1500; ++t) {
    const double cx = position(rng), cy = position(rng), cz = position(rng) * 0.2;
    const double scale = t % 100 == 0 ? 12.0 : 1.0;  // a few triangles span the whole soup
    for (int c = 0; c < 3; ++c) {
      mesh.xyz.push_back(std::round((cx + scale * offset(rng)) * 8) / 8);
      mesh.xyz.push_back(std::round((cy + scale * offset(rng)) * 8) / 8);
      mesh.xyz.push_back(std::round((cz + scale * offset(rng)) * 8) / 8);
    }
    const auto base = static_cast<Index>(3 * t);
    mesh.triangles.push_back({base, base + 1, base + 2});
  }
  return mesh;
}

// The soup shrunk to a centimetre and moved to georeferenced coordinates, both exactly (powers
// of two, then offsets whose sum keeps every bit): the same pairs. Float boxes taken at those
// coordinates as they are would be half a metre wide, the whole soup in one grid cell.
TEST(StatsCrossings, GeoreferencedCoordinatesGiveTheSameCounts) {
  const IndexedMesh soup = crossing_soup();
  IndexedMesh moved = soup;
  const double offset[3] = {512345.0, 5123456.0, 312.5};
  for (std::size_t k = 0; k < moved.xyz.size(); ++k) {
    moved.xyz[k] = std::ldexp(moved.xyz[k], -10) + offset[k % 3];
    ASSERT_EQ(moved.xyz[k] - offset[k % 3], std::ldexp(soup.xyz[k], -10));
  }
  const g2s::MeshStats s = g2s::compute_stats(soup), m = g2s::compute_stats(moved);
  EXPECT_GT(s.crossing_pairs, 100u);
  EXPECT_EQ(m.crossing_pairs, s.crossing_pairs);
  EXPECT_EQ(m.crossing_pairs_no_shared_vertex, s.crossing_pairs_no_shared_vertex);
  EXPECT_EQ(m.crossing_triangles, s.crossing_triangles);
}

TEST(StatsCrossings, GridAgreesWithAllPairs) {
  const IndexedMesh mesh = crossing_soup();
  const g2s::MeshStats s = g2s::compute_stats(mesh);
  // The same counts on one thread and on three (the caller's arena is respected).
  for (const int threads : {1, 3}) {
    tbb::task_arena arena(threads);
    const g2s::MeshStats t = arena.execute([&] { return g2s::compute_stats(mesh); });
    EXPECT_EQ(t.crossing_pairs, s.crossing_pairs) << threads;
    EXPECT_EQ(t.crossing_pairs_no_shared_vertex, s.crossing_pairs_no_shared_vertex) << threads;
    EXPECT_EQ(t.crossing_triangles, s.crossing_triangles) << threads;
  }

  // All pairs, sharing corners by position, as the stats weld them.
  std::vector<std::array<const double*, 3>> kept;
  for (const Triangle& t : mesh.triangles) {
    std::array<const double*, 3> c = {&mesh.xyz[3 * t[0]], &mesh.xyz[3 * t[1]],
                                      &mesh.xyz[3 * t[2]]};
    if (!g2s::exact::collinear(c[0], c[1], c[2])) kept.push_back(c);
  }
  ASSERT_EQ(kept.size(), s.triangles - s.degenerate_triangles);
  ASSERT_EQ(s.duplicate_triangles, 0u);
  std::uint64_t pairs = 0, apart = 0;
  std::vector<char> involved(kept.size(), 0);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    for (std::size_t j = i + 1; j < kept.size(); ++j) {
      if (!g2s::triangles_cross(kept[i].data(), kept[j].data())) continue;
      ++pairs;
      bool shares = false;
      for (const double* p : kept[i]) {
        for (const double* q : kept[j])
          shares = shares || (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]);
      }
      apart += shares ? 0 : 1;
      involved[i] = involved[j] = 1;
    }
  }
  EXPECT_GT(pairs, 100u);
  EXPECT_GT(pairs, apart);
  EXPECT_EQ(s.crossing_pairs, pairs);
  EXPECT_EQ(s.crossing_pairs_no_shared_vertex, apart);
  EXPECT_EQ(s.crossing_triangles,
            static_cast<std::uint64_t>(std::count(involved.begin(), involved.end(), 1)));
}

}  // namespace

// ---- Distances of the points left out ----

// A 5 x 5 grid of points at spacing 1 in z = 0, meshed by two triangles over its corners only,
// plus points above, beside and below it: the distances are known.
TEST(StatsPointDistances, KnownDistancesInSpacings) {
  const IndexedMesh mesh =
      mesh_of({{0, 0, 0}, {4, 0, 0}, {4, 4, 0}, {0, 4, 0}}, {{0, 1, 2}, {0, 2, 3}});
  g2s::PointCloud cloud;
  for (int y = 0; y <= 4; ++y) {
    for (int x = 0; x <= 4; ++x) cloud.xyz.insert(cloud.xyz.end(), {double(x), double(y), 0.0});
  }
  // 0.5, 1.5 and 3 above the middle, 5 beside the edge x = 4, 10 below the middle.
  cloud.xyz.insert(cloud.xyz.end(), {2, 2, 0.5, 2, 2, 1.5, 2, 2, 3, 9, 2, 0, 2, 2, -10});
  const g2s::MeshStats s = g2s::compute_stats(mesh, &cloud);
  ASSERT_TRUE(s.has_distances);
  EXPECT_EQ(s.covered_points, 4u);
  EXPECT_DOUBLE_EQ(s.spacing, 1.0);  // 24 of the 30 nearest-neighbour distances are 1
  EXPECT_EQ(s.off_mesh_points, 26u);
  EXPECT_EQ(s.off_mesh_within_1, 22u);  // the 21 grid points in the mesh, and 0.5
  EXPECT_EQ(s.off_mesh_within_2, 23u);
  EXPECT_EQ(s.off_mesh_within_4, 24u);
  EXPECT_EQ(s.off_mesh_beyond_4, 2u);
  EXPECT_DOUBLE_EQ(s.off_mesh_median, 0.0);
  EXPECT_DOUBLE_EQ(s.off_mesh_max, 10.0);
  EXPECT_DOUBLE_EQ(s.off_mesh_p99, 5.0);  // the 25th of 26 sorted distances
  // Isolated: 3 above (one point within 2, at 1.5), 5 beside and 10 below (none within 2). The
  // points at 0.5 and 1.5 above have more neighbours, and lie within 2 of the mesh.
  EXPECT_EQ(s.off_mesh_isolated, 3u);
  EXPECT_EQ(s.off_mesh_far_not_isolated, 0u);
  EXPECT_DOUBLE_EQ(s.surface_coverage, 4.0 / 27.0);

  const std::string json = g2s::stats_to_json(s);
  EXPECT_NE(json.find("\"off_mesh_beyond_4_spacings\": 2,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"off_mesh_isolated\": 3,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"off_mesh_distance_max\": 10\n}"), std::string::npos) << json;
  EXPECT_FALSE(g2s::compute_stats(mesh).has_distances);
}

// Distances through the tree equal those to every triangle, on a random soup and random points.
TEST(StatsPointDistances, TreeAgreesWithEveryTriangle) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> position(0.0, 10.0), offset(-0.5, 0.5);
  IndexedMesh mesh;
  for (int t = 0; t < 400; ++t) {
    const double cx = position(rng), cy = position(rng), cz = position(rng);
    for (int c = 0; c < 3; ++c) {
      mesh.xyz.insert(mesh.xyz.end(), {cx + offset(rng), cy + offset(rng), cz + offset(rng)});
    }
    const auto base = static_cast<Index>(3 * t);
    mesh.triangles.push_back({base, base + 1, base + 2});
  }
  g2s::PointCloud cloud;
  for (int i = 0; i < 300; ++i) {
    cloud.xyz.insert(cloud.xyz.end(), {3 * position(rng) - 10, position(rng), position(rng)});
  }
  const g2s::MeshStats s = g2s::compute_stats(mesh, &cloud);
  ASSERT_TRUE(s.has_distances);
  ASSERT_EQ(s.off_mesh_points, 300u);
  // The largest distance, by brute force over the triangles (sampled densely enough to be within
  // 1% of the exact one; the exact one is never larger than any sample).
  double largest = 0.0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3 p(cloud.xyz[3 * i], cloud.xyz[3 * i + 1], cloud.xyz[3 * i + 2]);
    double best = 1e300;
    for (const Triangle& t : mesh.triangles) {
      const Vec3 a(mesh.xyz[3 * t[0]], mesh.xyz[3 * t[0] + 1], mesh.xyz[3 * t[0] + 2]);
      const Vec3 b(mesh.xyz[3 * t[1]], mesh.xyz[3 * t[1] + 1], mesh.xyz[3 * t[1] + 2]);
      const Vec3 c(mesh.xyz[3 * t[2]], mesh.xyz[3 * t[2] + 1], mesh.xyz[3 * t[2] + 2]);
      for (int u = 0; u <= 40; ++u) {
        for (int v = 0; u + v <= 40; ++v) {
          const Vec3 q = a + (b - a) * (u / 40.0) + (c - a) * (v / 40.0);
          best = std::min(best, g2s::norm(q - p));
        }
      }
    }
    largest = std::max(largest, best);
  }
  EXPECT_LE(s.off_mesh_max * s.spacing, largest * (1 + 1e-12));
  EXPECT_GE(s.off_mesh_max * s.spacing, largest * 0.99);
}
