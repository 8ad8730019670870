// The tiled pipeline's writer against write_mesh: triangles streamed in orientation groups, some
// flipped at the end, must give the file write_mesh gives for the mesh with the flips applied,
// byte for byte, in every format. The mesh is large enough for binary STL's in-place rewrite to
// cross its windows and batches, with group runs of many lengths.
#include <gtest/gtest.h>

#include <cmath>
#include <iterator>
#include <numbers>

#include "g2s/io.hpp"
#include "support/temp_folder.hpp"

namespace {

namespace fs = std::filesystem;

using g2s::test_support::file_bytes;

// A torus as an n x m grid of quads, two triangles each; group runs of lengths 1..997.
struct GroupedMesh {
  std::vector<double> xyz;
  std::vector<g2s::Triangle> triangles;
  std::vector<std::uint32_t> group;
  std::vector<std::uint8_t> flip;  // per group
};

GroupedMesh grouped_torus(std::uint32_t n, std::uint32_t m) {
  GroupedMesh mesh;
  for (std::uint32_t i = 0; i < n; ++i) {
    for (std::uint32_t j = 0; j < m; ++j) {
      const double u = 2 * std::numbers::pi * i / n, v = 2 * std::numbers::pi * j / m;
      mesh.xyz.insert(mesh.xyz.end(), {(1 + 0.35 * std::cos(v)) * std::cos(u),
                                       (1 + 0.35 * std::cos(v)) * std::sin(u), 0.35 * std::sin(v)});
    }
  }
  auto at = [&](std::uint32_t i, std::uint32_t j) { return (i % n) * m + (j % m); };
  for (std::uint32_t i = 0; i < n; ++i) {
    for (std::uint32_t j = 0; j < m; ++j) {
      mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  std::uint32_t g = 0, left = 1;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (left-- == 0) {
      ++g;
      left = (g * 7919u) % 997u;
    }
    mesh.group.push_back(g % 50);  // groups come back: runs of one group are not contiguous
  }
  for (std::uint32_t k = 0; k < 50; ++k) mesh.flip.push_back(static_cast<std::uint8_t>(k % 3 == 1));
  return mesh;
}

void stream(const GroupedMesh& mesh, const fs::path& target, g2s::MeshFormat format) {
  g2s::MeshStreamWriter writer(target, format);
  std::vector<g2s::Index> number(mesh.xyz.size() / 3, g2s::kNoIndex);
  g2s::Index next = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    g2s::Triangle corners{};
    std::array<const double*, 3> xyz{};
    for (int c = 0; c < 3; ++c) {
      const g2s::Index v = mesh.triangles[t][c];
      if (number[v] == g2s::kNoIndex) {
        number[v] = next++;
        writer.vertex(v, &mesh.xyz[3 * std::size_t{v}]);
      }
      corners[c] = number[v];
      xyz[c] = &mesh.xyz[3 * std::size_t{v}];
    }
    writer.triangle(corners, xyz, mesh.group[t]);
  }
  writer.finish(mesh.flip);
}

TEST(MeshStreamWriter, GivesTheBytesOfWriteMeshWithTheFlipsApplied) {
  const g2s::test_support::TempFolder dir("g2s-stream");
  const GroupedMesh mesh = grouped_torus(700, 400);  // 560,000 triangles
  std::vector<g2s::Triangle> flipped = mesh.triangles;
  for (std::size_t t = 0; t < flipped.size(); ++t) {
    if (mesh.flip[mesh.group[t]]) std::swap(flipped[t][1], flipped[t][2]);
  }
  for (const auto& [format, name] : {std::pair{g2s::MeshFormat::stl_binary, "binary.stl"},
                                     std::pair{g2s::MeshFormat::stl_ascii, "ascii.stl"},
                                     std::pair{g2s::MeshFormat::ply_binary, "indexed.ply"}}) {
    SCOPED_TRACE(name);
    const fs::path streamed = dir.path() / (std::string("streamed-") + name);
    const fs::path expected = dir.path() / (std::string("expected-") + name);
    stream(mesh, streamed, format);
    g2s::write_mesh(expected, mesh.xyz, flipped, format);
    EXPECT_EQ(fs::file_size(streamed), fs::file_size(expected));
    if (format != g2s::MeshFormat::ply_binary) {
      EXPECT_TRUE(file_bytes(streamed) == file_bytes(expected)) << "the files differ";
      continue;
    }
    // PLY numbers vertices in order of first use as streamed, before the flips: the same
    // triangles, corner for corner, at the same positions.
    const g2s::IndexedMesh a = g2s::read_mesh(streamed), b = g2s::read_mesh(expected);
    ASSERT_EQ(a.triangles.size(), b.triangles.size());
    std::size_t differ = 0;
    for (std::size_t t = 0; t < a.triangles.size(); ++t) {
      for (int c = 0; c < 3; ++c) {
        for (int k = 0; k < 3; ++k) {
          differ += a.xyz[3 * std::size_t{a.triangles[t][c]} + k] !=
                    b.xyz[3 * std::size_t{b.triangles[t][c]} + k];
        }
      }
    }
    EXPECT_EQ(differ, 0u);
  }
  // Nothing left beside the outputs (spill files are temporaries).
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 6);
}

// The mesh as one block (MeshSink::prepare, then block), its vertices numbered in first use.
void stream_as_block(const GroupedMesh& mesh, const fs::path& target, g2s::MeshFormat format) {
  g2s::MeshStreamWriter writer(target, format);
  std::vector<g2s::Index> number(mesh.xyz.size() / 3, g2s::kNoIndex);
  std::vector<g2s::Index> ids;
  std::vector<double> xyz;
  std::vector<g2s::Triangle> triangles;
  for (const g2s::Triangle& t : mesh.triangles) {
    g2s::Triangle corners{};
    for (int c = 0; c < 3; ++c) {
      const g2s::Index v = t[c];
      if (number[v] == g2s::kNoIndex) {
        number[v] = static_cast<g2s::Index>(ids.size());
        ids.push_back(v);
        xyz.insert(xyz.end(), &mesh.xyz[3 * std::size_t{v}], &mesh.xyz[3 * std::size_t{v} + 3]);
      }
      corners[c] = number[v];
    }
    triangles.push_back(corners);
  }
  const g2s::SinkBlock block{ids, xyz, triangles, mesh.group, {}};
  writer.block(block, 0, 0, writer.prepare(block));
  writer.finish(mesh.flip);
}

// A block whose work the writer did ahead (binary STL: the facet normals) gives the bytes of the
// same triangles given one by one.
TEST(MeshStreamWriter, ABlockPreparedAheadGivesTheSameBytes) {
  const g2s::test_support::TempFolder dir("g2s-stream-block");
  const GroupedMesh mesh = grouped_torus(300, 200);
  for (const auto& [format, name] : {std::pair{g2s::MeshFormat::stl_binary, "binary.stl"},
                                     std::pair{g2s::MeshFormat::stl_ascii, "ascii.stl"},
                                     std::pair{g2s::MeshFormat::ply_binary, "indexed.ply"}}) {
    SCOPED_TRACE(name);
    const fs::path one_by_one = dir.path() / (std::string("single-") + name);
    const fs::path as_block = dir.path() / (std::string("block-") + name);
    stream(mesh, one_by_one, format);
    stream_as_block(mesh, as_block, format);
    EXPECT_TRUE(file_bytes(one_by_one) == file_bytes(as_block)) << "the files differ";
  }
}

TEST(MeshStreamWriter, LeavesNoFileWithoutTrianglesOrWhenNotFinished) {
  const g2s::test_support::TempFolder dir("g2s-stream");
  {
    g2s::MeshStreamWriter writer(dir.path() / "empty.stl", g2s::MeshFormat::stl_binary);
    writer.finish({});
  }
  {
    const GroupedMesh mesh = grouped_torus(10, 10);
    g2s::MeshStreamWriter writer(dir.path() / "abandoned.stl", g2s::MeshFormat::stl_binary);
    const double* p = mesh.xyz.data();
    writer.vertex(0, p);
    writer.triangle({0, 0, 0}, {p, p, p}, 0);
  }
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

}  // namespace
