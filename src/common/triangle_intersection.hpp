// Exact test of whether two triangles cross: whether the closed triangles meet anywhere other
// than in the corners or the edge they share (src/common/triangle_intersection.cpp). Used by
// `g2s stats` to count self-intersections and by the mesher to refuse a triangle that would cross
// a nearby one. Built on the exact predicates of exact_predicates.hpp: no tolerance, the answer
// is that of the exact coordinates given.
#pragma once

#include "common/vec3.hpp"

namespace g2s {

// Inputs: two triangles, each three corner positions (float converts to double exactly); both
// must be non-degenerate (their corners not collinear, exact::collinear false), and coordinates
// finite. Corners are shared when their three coordinates are equal (-0 equals +0); nothing else
// about the triangles (indices, orientation) matters.
// Output: true when the closed triangles intersect in more than what they share:
// - no shared corner: they have any point in common (touching at a point or along a segment
//   counts, e.g. a corner lying on the other's edge);
// - one shared corner: they have a point in common other than that corner;
// - a shared edge: they are coplanar and lie on the same side of the edge (folded flat onto
//   each other); otherwise they meet only in the edge;
// - three shared corners: always (the same triangle twice).
// Cost: a bounding-box test (18 comparisons) first; then, without shared corners, 3 filtered
// orient3d (about 40 flops each) reject a triangle lying on one side of the other's plane, and
// at most 24 run when the planes cross; with one shared corner 4 to 10, with a shared edge 1.
// No allocation. Measured (bench/stats_bench.cpp, BM_TrianglesCross, CPU time on a loaded
// machine) on float triangles of a sphere's mesh against the next 16 in mesher order: about 14 ns
// a call on average, 46 ns on the pairs whose boxes overlap (mostly neighbours). The exact
// fallback (about a microsecond) runs only for nearly degenerate configurations.
bool triangles_cross(const double* const a[3], const double* const b[3]);
bool triangles_cross(const Vec3 a[3], const Vec3 b[3]);
bool triangles_cross(const Vec3f a[3], const Vec3f b[3]);

}  // namespace g2s
