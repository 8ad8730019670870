// StreamStats, the defects counted while a mesh streams out, against compute_stats on the same
// mesh as the file holds it (orientation groups flipped at the end): a hand-made mesh with every
// kind of defect, random soups with welded positions, duplicates and degenerate triangles, and
// vertices announced done as early as possible or only at the end. Then `g2s mesh` itself: its
// summary against `g2s stats` on the file it wrote, STL and PLY, cut into many tiles.
#include "g2s/stream_stats.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "g2s/io.hpp"
#include "g2s/stats.hpp"
#include "support/cli.hpp"
#include "support/temp_folder.hpp"

namespace {

namespace fs = std::filesystem;
using g2s::IndexedMesh;
using g2s::MeshStats;
using g2s::Triangle;
using g2s::test_support::json_number;

class NullSink final : public g2s::MeshSink {
 public:
  void vertex(g2s::Index, const double[3]) override {}
  void triangle(const Triangle&, const std::array<const double*, 3>&, std::uint32_t) override {}
  void finish(std::span<const std::uint8_t>) override {}
};

// Hands triangle t of `mesh` to the counter one call at a time, numbering its new corners next.
void stream_triangle(g2s::StreamStats& counter, const IndexedMesh& mesh, std::size_t t,
                     std::uint32_t group, std::vector<std::uint32_t>& number, std::uint32_t& next) {
  Triangle numbers{};
  std::array<const double*, 3> xyz{};
  for (int k = 0; k < 3; ++k) {
    const g2s::Index v = mesh.triangles[t][k];
    xyz[k] = &mesh.xyz[3 * std::size_t{v}];
    if (number[v] == g2s::kNoIndex) {
      number[v] = next++;
      counter.vertex(v, xyz[k]);
    }
    numbers[k] = number[v];
  }
  counter.triangle(numbers, xyz, group);
}

// Streams `mesh` (triangles in `group`) through StreamStats as the pipeline does: each vertex
// numbered before its first triangle, announced done after its last one when `early` (else
// left to finish()), and the groups in `flip` reversed at the end.
MeshStats streamed(const IndexedMesh& mesh, const std::vector<std::uint32_t>& group,
                   const std::vector<std::uint8_t>& flip, bool early, bool* complete,
                   bool float_positions = false, bool positions_distinct = false) {
  NullSink null;
  g2s::StreamStats counter(null, float_positions, positions_distinct);
  // A vertex is done after the last triangle at its position (as stored): the pipeline gives
  // every vertex welded to another its number while that one is still open.
  std::map<std::array<double, 3>, std::size_t> last_at;
  auto position = [&](g2s::Index v) {
    std::array<double, 3> p{mesh.xyz[3 * v], mesh.xyz[3 * v + 1], mesh.xyz[3 * v + 2]};
    for (double& c : p) {
      if (float_positions) c = static_cast<double>(static_cast<float>(c));
      if (c == 0.0) c = 0.0;  // -0.0 welds to +0.0
    }
    return p;
  };
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (g2s::Index v : mesh.triangles[t]) last_at[position(v)] = t;
  }
  std::vector<std::vector<g2s::Index>> done_after(mesh.triangles.size());
  std::vector<std::uint8_t> used(mesh.vertex_count(), 0);
  for (const Triangle& t : mesh.triangles) {
    for (g2s::Index v : t) {
      if (!used[v]) done_after[last_at[position(v)]].push_back(v);
      used[v] = 1;
    }
  }
  std::vector<std::uint32_t> number(mesh.vertex_count(), g2s::kNoIndex);
  std::uint32_t next = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    stream_triangle(counter, mesh, t, group[t], number, next);
    if (!early) continue;
    for (g2s::Index v : done_after[t]) counter.vertex_done(number[v]);
  }
  counter.finish(flip);
  *complete = counter.complete();
  return counter.stats();
}

// The mesh as the file holds it: each triangle of a flipped group reversed.
IndexedMesh as_written(IndexedMesh mesh, const std::vector<std::uint32_t>& group,
                       const std::vector<std::uint8_t>& flip) {
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (flip[group[t]]) std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
  }
  return mesh;
}

// The vertices of a rows x columns grid on a torus (radii 3 and 1), row by row, each coordinate
// as `store` gives it.
template <class Store>
void add_torus_grid(IndexedMesh& mesh, std::uint32_t rows, std::uint32_t columns, Store store) {
  for (std::uint32_t r = 0; r < rows; ++r) {
    for (std::uint32_t c = 0; c < columns; ++c) {
      const double u = 2 * M_PI * c / columns, v = 2 * M_PI * r / rows;
      const double p[3] = {(3 + std::cos(v)) * std::cos(u), (3 + std::cos(v)) * std::sin(u),
                           std::sin(v)};
      for (double x : p) mesh.xyz.push_back(store(x));
    }
  }
}

// A torus grid of float coordinates with defects drawn from `seed`: holes (2%), reversed
// triangles (2%), and duplicates (1%), each followed by a fin on its first edge reaching 3 rows
// on. One orientation group per stripe of stripe_rows rows; a fin is in the next stripe's.
struct DefectiveTorus {
  IndexedMesh mesh;
  std::vector<std::uint32_t> group;
};
DefectiveTorus defective_torus(std::uint32_t rows, std::uint32_t columns, std::uint32_t stripe_rows,
                               unsigned seed) {
  DefectiveTorus torus;
  IndexedMesh& mesh = torus.mesh;
  add_torus_grid(mesh, rows, columns,
                 [](double x) { return static_cast<double>(static_cast<float>(x)); });
  auto at = [&](std::uint32_t r, std::uint32_t c) { return (r % rows) * columns + c % columns; };
  std::mt19937 random(seed);
  for (std::uint32_t r = 0; r < rows; ++r) {
    for (std::uint32_t c = 0; c < columns; ++c) {
      const Triangle a{at(r, c), at(r, c + 1), at(r + 1, c + 1)};
      const Triangle b{at(r, c), at(r + 1, c + 1), at(r + 1, c)};
      for (Triangle t : {a, b}) {
        const auto draw = static_cast<std::uint32_t>(random() % 100);
        if (draw < 2) continue;               // a hole
        if (draw < 4) std::swap(t[1], t[2]);  // reversed
        mesh.triangles.push_back(t);
        torus.group.push_back(r / stripe_rows);
        if (draw == 4) {  // a duplicate, then a fin on its first edge
          mesh.triangles.push_back({t[1], t[2], t[0]});
          mesh.triangles.push_back({t[0], t[1], at(r + 3, c + 7)});
          torus.group.push_back(r / stripe_rows);
          torus.group.push_back(r / stripe_rows + 1);
        }
      }
    }
  }
  return torus;
}

// a: counted in stride, which leaves crossings to g2s stats (and says so); b: compute_stats.
void expect_same(const MeshStats& a, MeshStats b, const std::string& what) {
  EXPECT_FALSE(a.has_crossings) << what;
  b.has_crossings = false;
  EXPECT_EQ(g2s::stats_to_json(a), g2s::stats_to_json(b)) << what;
}

TEST(StreamStats, EveryDefectKindAsComputeStatsCountsIt) {
  // A tetrahedron (groups 0 and 1, face 3 in group 1 wound the other way, so flipping group 1
  // fixes it), a fin on edge 0-1 (a third triangle: non-manifold edge), a reversed copy of face
  // 0, a collinear triangle, an open strip, and vertex 8 at vertex 0's position (welded).
  IndexedMesh mesh;
  mesh.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.5, -1, 0.5, 2, 0,
              0, 5, 5, 5, 6, 5, 5, 0, 0, 0, 5, 6, 5,   3,  0,   0};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3},  {1, 2, 3}, {0, 2, 3}, {0, 1, 4},
                    {0, 1, 2}, {1, 5, 10}, {6, 7, 9}, {8, 3, 2}, {7, 6, 9}};
  const std::vector<std::uint32_t> group = {0, 0, 0, 1, 2, 0, 0, 3, 1, 3};
  for (const std::vector<std::uint8_t>& flip :
       {std::vector<std::uint8_t>{0, 0, 0, 0}, std::vector<std::uint8_t>{0, 1, 0, 1}}) {
    const MeshStats expected = g2s::compute_stats(as_written(mesh, group, flip));
    ASSERT_GT(expected.non_manifold_edges, 0u);
    ASSERT_GT(expected.duplicate_triangles, 0u);
    ASSERT_GT(expected.degenerate_triangles, 0u);
    for (bool early : {false, true}) {
      bool complete = false;
      expect_same(streamed(mesh, group, flip, early, &complete), expected,
                  early ? "done early" : "done at the end");
      EXPECT_TRUE(complete);
    }
  }
}

TEST(StreamStats, RandomSoupsWithWeldedPositions) {
  std::mt19937 random(7);
  auto draw = [&](std::uint32_t below) { return static_cast<std::uint32_t>(random() % below); };
  for (int round = 0; round < 300; ++round) {
    const std::uint32_t points = 6 + draw(20);
    IndexedMesh mesh;
    for (std::uint32_t v = 0; v < points; ++v) {
      // Few distinct positions on a small grid, so that welding, collinear corners and
      // repeated vertex sets all occur.
      for (int k = 0; k < 3; ++k) mesh.xyz.push_back(static_cast<double>(draw(3)));
    }
    const std::size_t count = 1 + draw(40);
    std::vector<std::uint32_t> group;
    const std::uint32_t groups = 1 + draw(4);
    for (std::size_t t = 0; t < count; ++t) {
      mesh.triangles.push_back({draw(points), draw(points), draw(points)});
      group.push_back(draw(groups));
    }
    std::vector<std::uint8_t> flip(groups);
    for (auto& f : flip) f = static_cast<std::uint8_t>(draw(2));
    const MeshStats expected = g2s::compute_stats(as_written(mesh, group, flip));
    for (bool early : {false, true}) {
      bool complete = false;
      expect_same(streamed(mesh, group, flip, early, &complete), expected,
                  "round " + std::to_string(round) + (early ? ", done early" : ""));
      EXPECT_TRUE(complete);
    }
  }
}

// A closed grid surface (a torus) of 144,000 vertices, big enough for every path of the counter:
// the weld cells sized from the first 1,024 triangles, more than one chunk of vertex records,
// vertex numbers that stay open while more than the number window (131,072) passes (the first
// row waits for the last), stars judged by the one-pass test and, where defects are, by the
// general one. Defects: holes, a triangle reversed, a fin, duplicates, orientation groups in
// stripes with some flipped, coordinates snapped so that exact zeros of both signs occur, and
// twins of vertices at their positions (welded). With float positions (STL), twins 1e-12 away
// weld too.
TEST(StreamStats, LargeSurfaceWithDefectsAsComputeStatsCountsIt) {
  const std::uint32_t rows = 400, columns = 360;
  IndexedMesh mesh;
  add_torus_grid(mesh, rows, columns, [](double x) { return std::round(x * 1e3) / 1e3; });
  auto at = [&](std::uint32_t r, std::uint32_t c) { return (r % rows) * columns + c % columns; };
  std::vector<std::uint32_t> group;
  std::mt19937 random(11);
  for (std::uint32_t r = 0; r < rows; ++r) {
    for (std::uint32_t c = 0; c < columns; ++c) {
      const std::uint32_t stripe = r / 50;
      const Triangle a{at(r, c), at(r, c + 1), at(r + 1, c + 1)};
      const Triangle b{at(r, c), at(r + 1, c + 1), at(r + 1, c)};
      for (Triangle t : {a, b}) {
        const auto draw = static_cast<std::uint32_t>(random() % 1000);
        if (draw < 3) continue;               // a hole
        if (draw < 5) std::swap(t[1], t[2]);  // reversed
        if (draw < 7) {                       // a twin of a corner at its position
          mesh.xyz.insert(mesh.xyz.end(), mesh.xyz.begin() + 3 * t[0],
                          mesh.xyz.begin() + 3 * t[0] + 3);
          mesh.xyz[mesh.xyz.size() - 1] += (draw == 6 ? 1e-12 : 0.0);
          t[0] = static_cast<std::uint32_t>(mesh.vertex_count() - 1);
        }
        mesh.triangles.push_back(t);
        group.push_back(stripe);
        if (draw < 9 && draw >= 7) {  // a duplicate, then a fin on its first edge
          mesh.triangles.push_back({t[1], t[2], t[0]});
          mesh.triangles.push_back({t[0], t[1], at(r + 3, c + 7)});
          group.push_back(stripe);
          group.push_back(stripe + 1);
        }
      }
    }
  }
  std::vector<std::uint8_t> flip(rows / 50 + 2);
  for (std::size_t g = 0; g < flip.size(); ++g) flip[g] = g % 3 == 1;
  for (bool float_positions : {false, true}) {
    IndexedMesh stored = as_written(mesh, group, flip);
    if (float_positions) {
      for (double& x : stored.xyz) x = static_cast<double>(static_cast<float>(x));
    }
    const MeshStats expected = g2s::compute_stats(stored);
    ASSERT_GT(expected.boundary_edges, 0u);
    ASSERT_GT(expected.orientation_conflicts, 0u);
    ASSERT_GT(expected.non_manifold_edges, 0u);
    ASSERT_GT(expected.duplicate_triangles, 0u);
    for (bool early : {false, true}) {
      bool complete = false;
      expect_same(streamed(mesh, group, flip, early, &complete, float_positions), expected,
                  std::string(float_positions ? "float" : "double") +
                      (early ? ", done early" : ", done at the end"));
      EXPECT_TRUE(complete);
    }
  }
}

// Without welding (positions_distinct: no two vertices share a position, as for the pipeline's
// distinct input points), the counts are the same, on a torus of float coordinates with holes,
// reversed triangles, duplicates and fins.
TEST(StreamStats, DistinctPositionsNeedNoWelding) {
  const std::uint32_t rows = 120;
  const auto [mesh, group] = defective_torus(rows, 90, 30, 5);
  std::vector<std::uint8_t> flip(rows / 30 + 2);
  for (std::size_t g = 0; g < flip.size(); ++g) flip[g] = g % 2;
  const MeshStats expected = g2s::compute_stats(as_written(mesh, group, flip));
  ASSERT_GT(expected.holes, 0u);
  ASSERT_GT(expected.orientation_conflicts, 0u);
  ASSERT_GT(expected.non_manifold_edges, 0u);
  ASSERT_GT(expected.duplicate_triangles, 0u);
  for (bool float_positions : {false, true}) {
    for (bool early : {false, true}) {
      bool complete = false;
      expect_same(streamed(mesh, group, flip, early, &complete, float_positions, true), expected,
                  std::string(float_positions ? "float" : "double") +
                      (early ? ", done early" : ", done at the end"));
      EXPECT_TRUE(complete);
    }
  }
}

// The pipeline's way: each stripe's inner triangles (every corner in rows only that stripe uses)
// as one block of new vertices, counted ahead (prepare) where no welding is needed, then the
// triangles across the stripes one by one; each vertex done after its last triangle.
MeshStats streamed_in_blocks(const IndexedMesh& mesh, const std::vector<std::uint32_t>& group,
                             const std::vector<std::uint8_t>& flip, std::uint32_t columns,
                             std::uint32_t stripe_rows, bool positions_distinct,
                             bool* counted_ahead) {
  NullSink null;
  g2s::StreamStats counter(null, false, positions_distinct);
  const auto row = [&](g2s::Index v) { return v / columns; };
  const auto stripe_of = [&](const Triangle& t) -> std::uint32_t {
    for (g2s::Index v : t) {
      if (row(v) % stripe_rows == 0 || row(v) / stripe_rows != row(t[0]) / stripe_rows) {
        return g2s::kNoIndex;  // across stripes
      }
    }
    return row(t[0]) / stripe_rows;
  };
  std::vector<std::vector<std::size_t>> blocks;
  std::vector<std::size_t> across;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const std::uint32_t s = stripe_of(mesh.triangles[t]);
    if (s == g2s::kNoIndex) {
      across.push_back(t);
      continue;
    }
    if (blocks.size() <= s) blocks.resize(s + 1);
    blocks[s].push_back(t);
  }
  std::vector<std::size_t> order;
  for (const auto& b : blocks) order.insert(order.end(), b.begin(), b.end());
  order.insert(order.end(), across.begin(), across.end());
  std::vector<std::size_t> last(mesh.vertex_count(), 0);  // place in `order` of its last triangle
  for (std::size_t k = 0; k < order.size(); ++k) {
    for (g2s::Index v : mesh.triangles[order[k]]) last[v] = k;
  }
  std::vector<std::uint32_t> number(mesh.vertex_count(), g2s::kNoIndex);
  std::uint32_t next = 0;
  std::size_t at = 0;  // place in `order`
  *counted_ahead = true;
  for (const auto& b : blocks) {
    std::vector<g2s::Index> ids;
    std::vector<double> xyz;
    std::vector<Triangle> triangles;
    std::vector<std::uint32_t> block_group;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> done;
    std::vector<std::uint32_t> local(mesh.vertex_count(), g2s::kNoIndex);
    for (std::size_t k = 0; k < b.size(); ++k, ++at) {
      Triangle t = mesh.triangles[b[k]];
      for (g2s::Index& v : t) {
        if (local[v] == g2s::kNoIndex) {
          local[v] = static_cast<std::uint32_t>(ids.size());
          ids.push_back(v);
          xyz.insert(xyz.end(), &mesh.xyz[3 * std::size_t{v}], &mesh.xyz[3 * std::size_t{v} + 3]);
          number[v] = next + local[v];
        }
        if (last[v] == at) done.emplace_back(static_cast<std::uint32_t>(k), local[v]);
        v = local[v];
      }
      triangles.push_back(t);
      block_group.push_back(group[b[k]]);
    }
    const g2s::SinkBlock block{ids, xyz, triangles, block_group, done};
    std::unique_ptr<g2s::SinkBlockWork> work = counter.prepare(block);
    *counted_ahead = *counted_ahead && work != nullptr;
    counter.block(block, next, 0, std::move(work));
    next += static_cast<std::uint32_t>(ids.size());
  }
  for (; at < order.size(); ++at) {
    stream_triangle(counter, mesh, order[at], group[order[at]], number, next);
    for (g2s::Index v : mesh.triangles[order[at]]) {
      if (last[v] == at) counter.vertex_done(number[v]);
    }
  }
  counter.finish(flip);
  EXPECT_TRUE(counter.complete());
  return counter.stats();
}

// Blocks counted ahead give the counts of the same triangles streamed one by one: a torus of
// stripes (one orientation group each, every other one flipped) with holes, reversed triangles,
// duplicates and fins inside the stripes and across them. With welding, blocks go triangle by
// triangle, with the same counts.
TEST(StreamStats, BlocksCountedAheadAsComputeStatsCountsThem) {
  const std::uint32_t rows = 120, columns = 90, stripe_rows = 20;
  const auto [mesh, group] = defective_torus(rows, columns, stripe_rows, 7);
  std::vector<std::uint8_t> flip(rows / stripe_rows + 1);
  for (std::size_t g = 0; g < flip.size(); ++g) flip[g] = g % 2;
  const MeshStats expected = g2s::compute_stats(as_written(mesh, group, flip));
  ASSERT_GT(expected.holes, 0u);
  ASSERT_GT(expected.orientation_conflicts, 0u);
  ASSERT_GT(expected.non_manifold_edges, 0u);
  ASSERT_GT(expected.non_manifold_vertices, 0u);
  ASSERT_GT(expected.duplicate_triangles, 0u);
  for (bool distinct : {true, false}) {
    bool counted_ahead = false;
    expect_same(
        streamed_in_blocks(mesh, group, flip, columns, stripe_rows, distinct, &counted_ahead),
        expected, distinct ? "counted ahead" : "welded");
    EXPECT_EQ(counted_ahead, distinct);
  }
}

// `g2s mesh`'s own summary against `g2s stats` on the written file.
class MeshSummary : public ::testing::Test {
 protected:
  // Runs the CLI (through `prefix`, if any), expecting success; gives its stdout.
  std::string run(const std::vector<std::string>& args,
                  const std::vector<std::string>& prefix = {}) const {
    g2s::test_support::CliOptions options;
    options.prefix = prefix;
    const g2s::test_support::CliRun r = g2s::test_support::run_cli(dir_, args, options);
    EXPECT_EQ(r.code, 0) << r.err;
    return r.out;
  }
  // The object after "stats": in g2s mesh --json.
  static std::string stats_object(const std::string& json) {
    const std::size_t at = json.find("\"stats\":");
    if (at == std::string::npos) return "";
    const std::size_t begin = json.find('{', at);
    return json.substr(begin, json.find('}', begin) - begin + 1);
  }
  g2s::test_support::TempFolder folder_{"g2s-summary"};
  const fs::path dir_ = folder_.path();
};

// The PLY scans' coordinates are floats, so the count skips welding (for STL too); bun000
// shifted by 1e-10 and written as text is not, so STL's count welds.
TEST_F(MeshSummary, CountedInStrideAsGStatsCountsTheFile) {
  const char* scans[] = {"open-bunny-scan-bun000.ply", "open-autzen-lidar.ply", "raw-bunny.ply"};
  for (const char* scan : scans) G2S_SKIP_WITHOUT_DATA(g2s::test_support::data_dir() / scan);
  const g2s::PointCloud bun000 = g2s::read_points(g2s::test_support::data_dir() / scans[0]);
  const fs::path shifted = dir_ / "bun000-shifted.xyz";
  {
    std::FILE* out = std::fopen(shifted.c_str(), "w");
    ASSERT_NE(out, nullptr);
    for (std::size_t i = 0; i < bun000.size(); ++i) {
      const double* p = &bun000.xyz[3 * i];
      std::fprintf(out, "%.17g %.17g %.17g\n", p[0] + 1e-10, p[1] + 1e-10, p[2] + 1e-10);
    }
    std::fclose(out);
  }
  for (const fs::path& cloud :
       {g2s::test_support::data_dir() / scans[0], g2s::test_support::data_dir() / scans[1],
        g2s::test_support::data_dir() / scans[2], shifted}) {
    const std::string scan = cloud.filename().string();
    for (const char* extension : {".stl", ".ply"}) {
      const fs::path mesh = dir_ / (std::string("mesh") + extension);
      const std::string summary =
          run({"mesh", cloud.string(), "-o", mesh.string(), "--tile-points", "20000", "--json"});
      EXPECT_NE(summary.find("\"in_stride\":true"), std::string::npos) << summary;
      const std::string from_mesh = stats_object(summary);
      const std::string from_file = run({"stats", mesh.string(), "--json"});
      for (const char* key :
           {"triangles", "vertices", "degenerate_triangles", "duplicate_triangles",
            "non_manifold_edges", "boundary_edges", "orientation_conflicts",
            "non_manifold_vertices", "non_manifold_vertices_type1", "non_manifold_vertices_type2",
            "holes", "components"}) {
        EXPECT_EQ(json_number(from_mesh, key), json_number(from_file, key))
            << scan << extension << ": " << key;
      }
    }
  }
}

// From 8 threads the sink gets a thread of its own (SinkBehind): the file and every count are
// the same as with 2 threads, where it has none, and the JSON reports the thread's CPU.
TEST_F(MeshSummary, TheSinksOwnThreadChangesNoByteNorCount) {
  const fs::path cloud = g2s::test_support::data_dir() / "raw-bunny.ply";
  G2S_SKIP_WITHOUT_DATA(cloud);
  const auto sink_cpu = [](const std::string& json) {
    const std::size_t at = json.find("\"sink\":");
    return at == std::string::npos ? -1.0 : json_number(json.substr(at), "cpu");
  };
  for (const char* extension : {".stl", ".ply"}) {
    std::string summary[2], bytes[2];
    const char* threads[2] = {"2", "8"};
    for (int k = 0; k < 2; ++k) {
      const fs::path mesh = dir_ / (std::string("mesh-") + threads[k] + extension);
      summary[k] = run({"mesh", cloud.string(), "-o", mesh.string(), "--tile-points", "20000",
                        "--threads", threads[k], "--json"});
      std::ifstream in(mesh, std::ios::binary);
      bytes[k].assign(std::istreambuf_iterator<char>(in), {});
    }
    EXPECT_FALSE(bytes[0].empty());
    EXPECT_TRUE(bytes[0] == bytes[1]) << extension;
    EXPECT_EQ(stats_object(summary[0]), stats_object(summary[1])) << extension;
    EXPECT_EQ(sink_cpu(summary[0]), 0.0) << summary[0];
    EXPECT_GT(sink_cpu(summary[1]), 0.0) << summary[1];
  }
}

// The peak memory `g2s mesh` reports is the process's peak as the kernel measures it
// (/usr/bin/time), summary included: counted in stride (the counter's own peak, reported apart,
// is part of it) or read back (STL far from the origin, whose float rounding may weld vertices
// the stream kept apart). Before, the read-back came after the peak was taken: 207 MB reported,
// 339 MB measured on a 2M-point torus.
TEST_F(MeshSummary, ReportedPeakHoldsTheSummary) {
  using g2s::test_support::json_number;
  const fs::path peak = dir_ / "peak.txt";
  auto measured = [&](const std::vector<std::string>& args, double* peak_mb) {
    const std::string summary = run(args, {"/usr/bin/time", "-f", "%M", "-o", peak.string()});
    *peak_mb = std::strtod(g2s::test_support::file_bytes(peak).c_str(), nullptr) / 1024.0;
    return summary;
  };
  run({"synth", "torus", "-n", "200k", "-o", (dir_ / "torus.ply").string()});
  double peak_mb = 0;
  std::string summary = measured(
      {"mesh", (dir_ / "torus.ply").string(), "-o", (dir_ / "torus.ply.stl").string(), "--json"},
      &peak_mb);
  EXPECT_NE(summary.find("\"in_stride\":true"), std::string::npos) << summary;
  EXPECT_GE(json_number(summary, "peak_rss_mb"), peak_mb - 0.5) << summary;
  EXPECT_GT(json_number(summary, "counter_peak_mb"), 1.0) << summary;
  EXPECT_LT(json_number(summary, "counter_peak_mb"), json_number(summary, "peak_rss_mb"))
      << summary;

  // 300,000 points on a sphere of radius 200 (spacing 1.3) around (1e6, 1e6, 1e6), where float
  // steps by 0.06: the STL's rounding exceeds a hundredth of the spacing, so the file is read
  // back, in small tiles so that the read-back is the larger part of the peak.
  std::string text;
  const int n = 300000;
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(1.0 - z * z);
    const double a = 2.399963229728653 * i;
    text += std::to_string(1e6 + 200 * r * std::cos(a)) + " " +
            std::to_string(1e6 + 200 * r * std::sin(a)) + " " + std::to_string(1e6 + 200 * z) +
            "\n";
  }
  std::ofstream(dir_ / "far.xyz") << text;
  summary = measured({"mesh", (dir_ / "far.xyz").string(), "-o", (dir_ / "far.stl").string(),
                      "--tile-points", "20000", "--json"},
                     &peak_mb);
  EXPECT_NE(summary.find("\"in_stride\":false"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"stats\":"), std::string::npos) << summary;
  EXPECT_GE(json_number(summary, "peak_rss_mb"), peak_mb - 0.5) << summary;
}

}  // namespace
