// One binary STL facet record, shared by the streaming writers so that a facet written directly
// and one rewritten later (flipped in place) come out byte for byte the same.
#pragma once

#include <cstddef>
#include <filesystem>

namespace g2s {

inline constexpr std::size_t kStlHeaderBytes = 84;  // 80-byte header and the triangle count
inline constexpr std::size_t kStlRecordBytes = 50;

// Triangle (a, b, c) as 50 bytes: the normal (normalised cross product of the float corners;
// zero for a degenerate facet), the corners as float, a zero attribute.
void stl_record(const double a[3], const double b[3], const double c[3], char record[50]);
// The normal stl_record writes for (a, b, c), worked out apart (ahead, on another thread), and
// the record with it given: the same 50 bytes as stl_record.
void stl_normal(const double a[3], const double b[3], const double c[3], float normal[3]);
void stl_record(const double a[3], const double b[3], const double c[3], const float normal[3],
                char record[50]);
// Throws Error(usage) naming `target` when the coordinate turns infinite as a 32-bit float: STL
// cannot hold it, PLY (double where needed) can.
void require_stl_coordinate(const std::filesystem::path& target, double value);

}  // namespace g2s
