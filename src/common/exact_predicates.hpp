// Exact orientation predicates on double coordinates: the sign of a 2x2 or 3x3 determinant,
// decided by a floating-point filter (Shewchuk's static bound on the rounded determinant) and,
// when the filter cannot tell, recomputed exactly with floating-point expansions (sums of
// non-overlapping doubles; src/common/exact_predicates.cpp). Never a tolerance: the sign is that
// of the exact determinant of the given doubles, as long as no product over- or underflows
// (coordinate differences between about 1e-100 and 1e100 in magnitude, or exactly 0). Float
// coordinates convert to double exactly, so the same functions serve float meshes.
#pragma once

namespace g2s::exact {

// +1, 0 or -1: the sign of det[b-a, c-a, d-a] (rows), i.e. +1 when d lies on the side of the
// plane through a, b, c that the normal (b-a) x (c-a) points to, 0 when the four are coplanar.
int orient3d(const double* a, const double* b, const double* c, const double* d);

// +1, 0 or -1: the sign of (b-a) x (c-a) in the plane of coordinates (i, j) of each point, i.e.
// +1 when a, b, c turn counter-clockwise seen with axis i to the right and axis j up.
// i, j in {0, 1, 2}, i != j.
int orient2d(const double* a, const double* b, const double* c, int i, int j);

// True when a, b, c lie on one line (or two of them coincide), exactly.
bool collinear(const double* a, const double* b, const double* c);

}  // namespace g2s::exact
