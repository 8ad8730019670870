// `peer_cgal_self_intersections MESH`: CGAL's count of a mesh's self-intersecting triangle pairs,
// to check `g2s stats`' crossing counts against (bench/check_self_intersections.py). Prints one
// JSON line: {"triangles": faces given to CGAL, "pairs": pairs CGAL reports,
// "pairs_no_shared_vertex": those whose triangles have no corner position in common, "seconds":
// CGAL's time}.
//
// The mesh is read with g2s::read_mesh, its corners welded by exact position, and the triangles
// g2s stats leaves out are left out here too: degenerate ones (CGAL::collinear, exact) and later
// copies of a vertex set. CGAL's Polygon_mesh_processing::self_intersections needs a polygon
// mesh, so the soup is made one with orient_polygon_soup, which may reverse faces and duplicate
// non-manifold vertices (copies at the same position). Pairs sharing a corner are therefore
// compared by position: CGAL tests pairs with no shared vertex by Do_intersect_3 on the closed
// triangles (exact predicates), which is the definition of g2s stats' pairs sharing no vertex.
// Pairs sharing a vertex or edge are judged by its own rules on the halfedge structure, whose
// vertices may have been split, so "pairs" is not comparable to g2s's all-pairs count.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <exception>
#include <map>
#include <set>
#include <vector>

#include "g2s/error.hpp"
#include "g2s/io.hpp"

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

int run(const char* path) {
  const g2s::IndexedMesh input = g2s::read_mesh(path);
  std::vector<Point> points;
  std::map<std::array<double, 3>, std::size_t> weld;  // -0 folded onto +0
  std::vector<std::size_t> id(input.vertex_count());
  for (std::size_t v = 0; v < input.vertex_count(); ++v) {
    std::array<double, 3> key;
    for (int k = 0; k < 3; ++k) {
      const double d = input.xyz[3 * v + k];
      key[k] = d == 0.0 ? 0.0 : d;
    }
    const auto [it, fresh] = weld.emplace(key, points.size());
    if (fresh) points.emplace_back(key[0], key[1], key[2]);
    id[v] = it->second;
  }
  std::vector<std::vector<std::size_t>> polygons;
  std::set<std::array<std::size_t, 3>> seen;
  for (const g2s::Triangle& t : input.triangles) {
    std::array<std::size_t, 3> corner = {id[t[0]], id[t[1]], id[t[2]]};
    if (CGAL::collinear(points[corner[0]], points[corner[1]], points[corner[2]])) continue;
    std::array<std::size_t, 3> sorted = corner;
    std::sort(sorted.begin(), sorted.end());
    if (!seen.insert(sorted).second) continue;
    polygons.push_back({corner[0], corner[1], corner[2]});
  }

  const auto start = std::chrono::steady_clock::now();
  PMP::orient_polygon_soup(points, polygons);
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  PMP::self_intersections(mesh, std::back_inserter(pairs));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  auto corners = [&](Mesh::Face_index f) {
    std::array<Point, 3> out;
    int k = 0;
    for (const Mesh::Vertex_index v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
      out[k++] = mesh.point(v);
    }
    return out;
  };
  std::size_t apart = 0;
  for (const auto& [f, g] : pairs) {
    const std::array<Point, 3> a = corners(f), b = corners(g);
    bool shares = false;
    for (const Point& p : a) shares = shares || p == b[0] || p == b[1] || p == b[2];
    if (!shares) ++apart;
  }
  std::printf("{\"triangles\":%zu,\"pairs\":%zu,\"pairs_no_shared_vertex\":%zu,\"seconds\":%.3f}\n",
              static_cast<std::size_t>(mesh.number_of_faces()), pairs.size(), apart, seconds);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s MESH\n", argv[0]);
    return static_cast<int>(g2s::Exit::usage);
  }
  try {
    return run(argv[1]);
  } catch (const g2s::Error& e) {
    std::fprintf(stderr, "peer_cgal_self_intersections: %s\n", e.what());
    return static_cast<int>(e.code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "peer_cgal_self_intersections: %s\n", e.what());
    return static_cast<int>(g2s::Exit::failure);
  }
}
