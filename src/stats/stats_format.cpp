// MeshStats as JSON (for scripts and CI: one object, keys always in the same order) and as
// aligned text (for people). Both list the same numbers under the same names.
#include <fmt/core.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "g2s/stats.hpp"

namespace g2s {
namespace {

// The counts in report order: JSON key, label for people.
struct Field {
  std::string_view key;
  std::string_view label;
  std::uint64_t value;
};

std::vector<Field> fields(const MeshStats& s) {
  std::vector<Field> out = {
      {"triangles", "triangles", s.triangles},
      {"vertices", "vertices", s.vertices},
      {"degenerate_triangles", "degenerate triangles", s.degenerate_triangles},
      {"duplicate_triangles", "duplicate triangles", s.duplicate_triangles},
      {"non_manifold_edges", "non-manifold edges", s.non_manifold_edges},
      {"non_manifold_vertices", "non-manifold vertices", s.non_manifold_vertices},
      {"non_manifold_vertices_type1", "  type I (a fan closed)", s.non_manifold_vertices_type1},
      {"non_manifold_vertices_type2", "  type II (all fans open)", s.non_manifold_vertices_type2},
      {"boundary_edges", "boundary edges", s.boundary_edges},
      {"holes", "holes", s.holes},
      {"orientation_conflicts", "orientation conflicts", s.orientation_conflicts},
      {"components", "components", s.components},
  };
  if (s.has_crossings) {
    out.push_back({"crossing_pairs", "crossing triangle pairs", s.crossing_pairs});
    out.push_back({"crossing_pairs_no_shared_vertex", "  sharing no vertex",
                   s.crossing_pairs_no_shared_vertex});
    out.push_back({"crossing_triangles", "crossing triangles", s.crossing_triangles});
  }
  if (s.has_coverage) {
    out.push_back({"input_points", "input points", s.input_points});
    out.push_back({"covered_points", "covered points", s.covered_points});
  }
  if (s.has_distances) {
    out.push_back({"off_mesh_points", "points off the mesh", s.off_mesh_points});
    out.push_back({"off_mesh_within_1_spacing", "  within 1 spacing", s.off_mesh_within_1});
    out.push_back({"off_mesh_within_2_spacings", "  within 2 spacings", s.off_mesh_within_2});
    out.push_back({"off_mesh_within_4_spacings", "  within 4 spacings", s.off_mesh_within_4});
    out.push_back({"off_mesh_beyond_4_spacings", "  beyond 4 spacings", s.off_mesh_beyond_4});
    out.push_back({"off_mesh_isolated", "  isolated (outliers)", s.off_mesh_isolated});
    out.push_back(
        {"off_mesh_far_not_isolated", "  beyond 2, not isolated", s.off_mesh_far_not_isolated});
  }
  return out;
}

// The real-valued results of the point distances, after the counts: JSON key, label, value.
struct Measure {
  std::string_view key;
  std::string_view label;
  double value;
};

std::vector<Measure> measures(const MeshStats& s) {
  std::vector<Measure> out;
  if (s.has_distances) {
    out = {{"spacing", "spacing", s.spacing},
           {"off_mesh_distance_median", "median distance/spacing", s.off_mesh_median},
           {"off_mesh_distance_p90", "90% distance/spacing", s.off_mesh_p90},
           {"off_mesh_distance_p99", "99% distance/spacing", s.off_mesh_p99},
           {"off_mesh_distance_max", "max distance/spacing", s.off_mesh_max}};
  }
  return out;
}

}  // namespace

std::string stats_to_json(const MeshStats& stats) {
  std::string out = "{";
  const char* separator = "\n";
  for (const Field& f : fields(stats)) {
    out += fmt::format("{}  \"{}\": {}", separator, f.key, f.value);
    separator = ",\n";
  }
  // {} prints the shortest decimal that reads back as the same double: valid JSON, no NaN.
  if (stats.has_coverage) out += fmt::format(",\n  \"coverage\": {}", stats.coverage);
  if (stats.has_distances) {
    out += fmt::format(",\n  \"surface_coverage\": {}", stats.surface_coverage);
  }
  for (const Measure& m : measures(stats)) out += fmt::format(",\n  \"{}\": {}", m.key, m.value);
  out += "\n}";
  return out;
}

std::string stats_to_text(const MeshStats& stats) {
  std::string out;
  for (const Field& f : fields(stats)) out += fmt::format("{:<26}{:>14}\n", f.label, f.value);
  if (stats.has_coverage) {
    out += fmt::format("{:<26}{:>13.3f}%\n", "coverage", 100.0 * stats.coverage);
  }
  if (stats.has_distances) {
    out += fmt::format("{:<26}{:>13.3f}%\n", "  isolated points aside",
                       100.0 * stats.surface_coverage);
  }
  for (const Measure& m : measures(stats))
    out += fmt::format("{:<26}{:>14.4g}\n", m.label, m.value);
  return out;
}

}  // namespace g2s
