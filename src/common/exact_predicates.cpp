// Exact orientation predicates (exact_predicates.hpp). The determinant is first evaluated in
// double with an a-priori error bound (Shewchuk 1997, "Adaptive precision floating-point
// arithmetic and fast robust geometric predicates", bounds A of orient2d and orient3d); only when
// |det| is within the bound is it recomputed exactly as an expansion: a sum of doubles with
// non-overlapping mantissas, in increasing magnitude, whose largest component has the sign of the
// sum. Coordinate differences are kept exact as two-component expansions, products by Dekker's
// splitting. Everything lives on the stack (at most 192 components for orient3d). This file is
// compiled with -ffp-contract=off (CMakeLists.txt): a fused multiply-add would break the
// error-free transformations.
#include "common/exact_predicates.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

namespace g2s::exact {
namespace {

constexpr double kEpsilon = 0x1p-53;  // half an ulp of 1: the unit roundoff
constexpr double kSplitter = 0x1p27 + 1.0;
constexpr double kOrient2dBound = (3.0 + 16.0 * kEpsilon) * kEpsilon;
constexpr double kOrient3dBound = (7.0 + 56.0 * kEpsilon) * kEpsilon;

// a + b = x + y exactly, x = fl(a + b).
inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double b_virtual = x - a;
  const double a_virtual = x - b_virtual;
  y = (a - a_virtual) + (b - b_virtual);
}

// a - b = x + y exactly, x = fl(a - b).
inline void two_diff(double a, double b, double& x, double& y) {
  x = a - b;
  const double b_virtual = a - x;
  const double a_virtual = x + b_virtual;
  y = (a - a_virtual) + (b_virtual - b);
}

// a = hi + lo with hi and lo of at most 26 significant bits each.
inline void split(double a, double& hi, double& lo) {
  const double c = kSplitter * a;
  const double big = c - a;
  hi = c - big;
  lo = a - hi;
}

// a * b = x + y exactly, x = fl(a * b).
inline void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  double a_hi, a_lo, b_hi, b_lo;
  split(a, a_hi, a_lo);
  split(b, b_hi, b_lo);
  const double err1 = x - a_hi * b_hi;
  const double err2 = err1 - a_lo * b_hi;
  const double err3 = err2 - a_hi * b_lo;
  y = a_lo * b_lo - err3;
}

// An expansion on the stack: components in increasing magnitude, zeros eliminated (but at least
// one component).
template <int Capacity>
struct Expansion {
  double c[Capacity];
  int n = 0;
  int sign() const { return c[n - 1] > 0 ? 1 : (c[n - 1] < 0 ? -1 : 0); }
};

// e += b (Shewchuk's GROW-EXPANSION with zero elimination), in place.
template <int Capacity>
void grow(Expansion<Capacity>& e, double b) {
  double q = b;
  int out = 0;
  for (int i = 0; i < e.n; ++i) {
    double sum, error;
    two_sum(q, e.c[i], sum, error);
    q = sum;
    if (error != 0.0) e.c[out++] = error;
  }
  if (q != 0.0 || out == 0) e.c[out++] = q;
  e.n = out;
}

// e += f, one component of f at a time.
template <int Capacity, int Other>
void add(Expansion<Capacity>& e, const Expansion<Other>& f) {
  for (int i = 0; i < f.n; ++i) grow(e, f.c[i]);
}

template <int Capacity>
void negate(Expansion<Capacity>& e) {
  for (int i = 0; i < e.n; ++i) e.c[i] = -e.c[i];
}

// out = e * b (Shewchuk's SCALE-EXPANSION with zero elimination).
template <int Capacity, int Out>
void scale(const Expansion<Capacity>& e, double b, Expansion<Out>& out) {
  static_assert(Out >= 2 * Capacity);
  double q, error;
  two_product(e.c[0], b, q, error);
  out.n = 0;
  if (error != 0.0) out.c[out.n++] = error;
  for (int i = 1; i < e.n; ++i) {
    double product_hi, product_lo, sum;
    two_product(e.c[i], b, product_hi, product_lo);
    two_sum(q, product_lo, sum, error);
    if (error != 0.0) out.c[out.n++] = error;
    // |product_hi| >= |sum| here, so the fast two-sum would do; the plain one is as exact.
    two_sum(product_hi, sum, q, error);
    if (error != 0.0) out.c[out.n++] = error;
  }
  if (q != 0.0 || out.n == 0) out.c[out.n++] = q;
}

// out = e * f.
template <int A, int B, int Out>
void multiply(const Expansion<A>& e, const Expansion<B>& f, Expansion<Out>& out) {
  static_assert(Out >= 2 * A * B);
  out.n = 0;
  Expansion<2 * A> partial;
  for (int i = 0; i < f.n; ++i) {
    scale(e, f.c[i], partial);
    add(out, partial);
  }
  if (out.n == 0) out.c[out.n++] = 0.0;
}

// a - b, exactly.
Expansion<2> difference(double a, double b) {
  Expansion<2> d;
  double x, y;
  two_diff(a, b, x, y);
  if (y != 0.0) d.c[d.n++] = y;
  d.c[d.n++] = x;
  return d;
}

// p * s - q * r for two-component p, q, r, s.
Expansion<16> minor2(const Expansion<2>& p, const Expansion<2>& s, const Expansion<2>& q,
                     const Expansion<2>& r) {
  Expansion<16> out;
  multiply(p, s, out);
  Expansion<8> second;
  multiply(q, r, second);
  negate(second);
  add(out, second);
  return out;
}

// The integer fast path: when every coordinate difference is exact in double (as for float
// input) and all of them are whole multiples of one power of two 2^e spanning at most `bits`
// bits above it, they are scaled to integers and the determinant is taken in 128-bit integer
// arithmetic, exactly, far faster than expansions. Exactly coplanar or collinear points (flat
// scans quantised by their scanner) reach the exact stage on every call, so this is what they
// cost.
// x = mantissa * 2^exponent with an integer mantissa of at most 53 bits (x finite).
struct Binary {
  std::int64_t mantissa;
  int exponent;
};
Binary binary(double x) {
  const auto bits = std::bit_cast<std::uint64_t>(x);
  const int biased = static_cast<int>(bits >> 52 & 0x7FF);
  std::uint64_t mantissa = bits & ((std::uint64_t{1} << 52) - 1);
  if (biased != 0) mantissa |= std::uint64_t{1} << 52;
  const auto magnitude = static_cast<std::int64_t>(mantissa);
  return {bits >> 63 ? -magnitude : magnitude, std::max(biased, 1) - 1075};
}

// Scales the n exact differences to integers in `out`; false when they span more than `bits`.
bool to_integers(const double* d, int n, int bits, std::int64_t* out) {
  Binary b[9];
  int low = 1 << 20, high = -(1 << 20);
  for (int k = 0; k < n; ++k) {
    b[k] = binary(d[k]);
    if (b[k].mantissa == 0) continue;
    const auto magnitude = static_cast<std::uint64_t>(std::abs(b[k].mantissa));
    low = std::min(low, b[k].exponent + std::countr_zero(magnitude));
    high = std::max(high, b[k].exponent + 63 - std::countl_zero(magnitude));
  }
  if (high - low + 1 > bits) return false;
  for (int k = 0; k < n; ++k) {
    if (b[k].mantissa == 0) {
      out[k] = 0;
      continue;
    }
    // exponent - low >= -(trailing zeros of the mantissa), so a right shift drops only zeros;
    // and the shifted value has fewer than `bits` bits, so no shift reaches 64.
    const int shift = b[k].exponent - low;
    out[k] = shift >= 0 ? b[k].mantissa * (std::int64_t{1} << shift)
                        : b[k].mantissa / (std::int64_t{1} << -shift);
  }
  return true;
}

// The differences b - a, when exact.
bool exact_differences(const double* b, const double* a, int n, double* out) {
  for (int k = 0; k < n; ++k) {
    double tail;
    two_diff(b[k], a[k], out[k], tail);
    if (tail != 0.0) return false;
  }
  return true;
}

__extension__ typedef __int128 Int128;  // GCC and Clang on 64-bit targets

int sign(Int128 x) {
  return x > 0 ? 1 : (x < 0 ? -1 : 0);
}

int orient2d_exact(const double* a, const double* b, const double* c, int i, int j) {
  {
    const double pb[2] = {b[i], b[j]}, pc[2] = {c[i], c[j]}, pa[2] = {a[i], a[j]};
    double d[4];
    std::int64_t n[4];
    // 2 * 62 bits + 1 fits 127.
    if (exact_differences(pb, pa, 2, d) && exact_differences(pc, pa, 2, d + 2) &&
        to_integers(d, 4, 62, n)) {
      return sign(static_cast<Int128>(n[0]) * n[3] - static_cast<Int128>(n[1]) * n[2]);
    }
  }
  const Expansion<2> ui = difference(b[i], a[i]), uj = difference(b[j], a[j]);
  const Expansion<2> vi = difference(c[i], a[i]), vj = difference(c[j], a[j]);
  return minor2(ui, vj, uj, vi).sign();
}

int orient3d_exact(const double* a, const double* b, const double* c, const double* d) {
  {
    double diff[9];
    std::int64_t n[9];
    // Three factors of 41 bits and a sum of six terms: 123 + 3 bits fit 127.
    if (exact_differences(b, a, 3, diff) && exact_differences(c, a, 3, diff + 3) &&
        exact_differences(d, a, 3, diff + 6) && to_integers(diff, 9, 41, n)) {
      const std::int64_t *u = n, *v = n + 3, *w = n + 6;
      Int128 det = 0;
      for (int k = 0; k < 3; ++k) {
        const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
        const Int128 minor =
            static_cast<Int128>(u[k1]) * v[k2] - static_cast<Int128>(u[k2]) * v[k1];
        det += minor * w[k];
      }
      return sign(det);
    }
  }
  Expansion<2> u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = difference(b[k], a[k]);
    v[k] = difference(c[k], a[k]);
    w[k] = difference(d[k], a[k]);
  }
  // det = w . (u x v), expanded along w.
  Expansion<192> det;
  Expansion<64> term;
  for (int k = 0; k < 3; ++k) {
    const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
    multiply(minor2(u[k1], v[k2], u[k2], v[k1]), w[k], term);
    add(det, term);
  }
  return det.sign();
}

}  // namespace

int orient2d(const double* a, const double* b, const double* c, int i, int j) {
  const double left = (b[i] - a[i]) * (c[j] - a[j]);
  const double right = (b[j] - a[j]) * (c[i] - a[i]);
  const double det = left - right;
  const double bound = kOrient2dBound * (std::fabs(left) + std::fabs(right));
  if (det > bound) return 1;
  if (-det > bound) return -1;
  return orient2d_exact(a, b, c, i, j);
}

int orient3d(const double* a, const double* b, const double* c, const double* d) {
  const double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
  const double vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
  const double wx = d[0] - a[0], wy = d[1] - a[1], wz = d[2] - a[2];
  const double uyvz = uy * vz, uzvy = uz * vy;
  const double uzvx = uz * vx, uxvz = ux * vz;
  const double uxvy = ux * vy, uyvx = uy * vx;
  const double det = wx * (uyvz - uzvy) + wy * (uzvx - uxvz) + wz * (uxvy - uyvx);
  const double permanent = (std::fabs(uyvz) + std::fabs(uzvy)) * std::fabs(wx) +
                           (std::fabs(uzvx) + std::fabs(uxvz)) * std::fabs(wy) +
                           (std::fabs(uxvy) + std::fabs(uyvx)) * std::fabs(wz);
  const double bound = kOrient3dBound * permanent;
  if (det > bound) return 1;
  if (-det > bound) return -1;
  // Four points with one coordinate in common lie in a plane parallel to an axis: quantized
  // scans (depth images, LAS's integer coordinates) give many such exact zeros, which the
  // filter can never decide.
  for (int k = 0; k < 3; ++k) {
    if (a[k] == b[k] && a[k] == c[k] && a[k] == d[k]) return 0;
  }
  return orient3d_exact(a, b, c, d);
}

bool collinear(const double* a, const double* b, const double* c) {
  return orient2d(a, b, c, 0, 1) == 0 && orient2d(a, b, c, 1, 2) == 0 &&
         orient2d(a, b, c, 2, 0) == 0;
}

}  // namespace g2s::exact
