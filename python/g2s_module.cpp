// The Python module g2s (pybind11, numpy): the library's three ways of use from Python.
//   g2s.mesh(points, ...)          -> (triangles, summary): an (N, 3) array meshed in memory,
//                                     tiled and parallel like `g2s mesh`, the GIL released
//   g2s.mesh_file(input, output, ...) -> summary: the out-of-core pipeline, file to file, the
//                                     defects counted as the mesh streams out
//   g2s.stats(points, triangles)   -> dict: g2s stats' counts
// Options are the CLI's (`--max-fold` is max_fold=...). g2s::Error becomes g2s.Error (or its
// subclass for the exit code) with the CLI's message, without its "g2s: error: " prefix.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/pipeline.hpp"
#include "g2s/stats.hpp"
#include "g2s/stream_stats.hpp"
#include "g2s/surface_check.hpp"
#include "g2s/tile_store.hpp"

namespace py = pybind11;

namespace {

// The mesher's options as keyword arguments, named as the CLI's flags.
struct MesherArgs {
  std::optional<std::vector<double>> radius_steps;
  int flatness_levels = 4;
  double max_fold = 135.0;
  double max_radius = 6.0;
  bool keep_gaps = false;
  int max_hole_edges = 30;
  int max_hole_rings = 3;
  bool no_orient = false;
};

g2s::PipelineOptions pipeline_options(const MesherArgs& m, int threads) {
  g2s::PipelineOptions options;
  if (m.radius_steps) options.mesh.radius_steps = *m.radius_steps;
  options.mesh.flatness_levels = m.flatness_levels;
  options.mesh.max_fold_deg = m.max_fold;
  options.mesh.max_radius = m.max_radius;
  options.mesh.close_gaps = !m.keep_gaps;
  options.mesh.max_hole_edges = m.max_hole_edges;
  options.mesh.max_hole_rings = m.max_hole_rings;
  options.mesh.orient = !m.no_orient;
  options.threads = threads;
  return options;
}

std::uint64_t budget_of(std::optional<std::uint64_t> memory) {
  return memory ? *memory : g2s::default_memory_budget();
}

// An (N, 3) float32/float64 array as the library's cloud: 3 doubles a point. The library's
// clouds own their coordinates, so this is the one copy (float64 in C order is copied as it is,
// anything else converted on the way).
g2s::PointCloud cloud_from(const py::array& points) {
  if (!py::isinstance<py::array_t<float>>(points) && !py::isinstance<py::array_t<double>>(points)) {
    throw py::type_error("points: expected a float32 or float64 array, got dtype " +
                         std::string(py::str(points.dtype())));
  }
  if (points.ndim() != 2 || points.shape(1) != 3) {
    throw py::value_error("points: expected an (N, 3) array, got " +
                          std::string(py::str(points.attr("shape"))));
  }
  const auto n = static_cast<std::size_t>(points.shape(0));
  if (n > g2s::kNoIndex) throw g2s::Error(g2s::Exit::bad_input, "points: more than 2^32-1 points");
  const auto doubles =
      py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(points);
  g2s::PointCloud cloud;
  cloud.xyz.assign(doubles.data(), doubles.data() + 3 * n);
  return cloud;
}

// Leaves out the points with a NaN or Inf coordinate, as the readers do; returns for each point
// kept its row in the array, or nothing when every point is kept.
std::vector<g2s::Index> drop_non_finite(g2s::PointCloud& cloud) {
  std::vector<g2s::Index> rows;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double* p = &cloud.xyz[3 * i];
    if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])) {
      if (kept != i) std::copy(p, p + 3, &cloud.xyz[3 * kept]);
      rows.push_back(static_cast<g2s::Index>(i));
      ++kept;
    }
  }
  if (kept == cloud.size()) return {};
  cloud.xyz.resize(3 * kept);
  return rows;
}

py::dict parse_json(const std::string& json) {
  return py::module_::import("json").attr("loads")(json);
}

py::dict report_dict(const g2s::PipelineSummary& s) {
  py::dict d;
  d["points"] = s.report.points;
  d["triangles"] = s.triangles;
  d["vertices"] = s.vertices;
  d["duplicates_merged"] = s.report.duplicates_merged;
  d["spacing"] = s.report.spacing;
  d["seeds"] = s.report.seeds;
  d["triangles_removed"] = s.report.triangles_removed;
  d["tiles"] = s.tiles;
  d["triangles_stitched"] = s.triangles_stitched;
  d["seam_triangles_dropped"] = s.seam_triangles_dropped;
  return d;
}

// The CLI's words when nothing could be meshed ("<input>: no surface can be formed: ...").
[[noreturn]] void throw_no_surface(const std::string& input, const g2s::PointCloud& cloud,
                                   std::uint64_t points, std::uint64_t non_finite) {
  std::string why = g2s::why_no_surface(cloud);
  if (why.empty()) {
    why = "no triangle found among " + std::to_string(points) +
          " points (too sparse for --max-radius?)";
  }
  if (non_finite > 0) {
    why += " (" + std::to_string(non_finite) + " points with NaN or Inf coordinates dropped)";
  }
  throw g2s::Error(g2s::Exit::no_surface,
                   input + ": no surface can be formed: " + why + "; nothing written");
}

std::pair<py::array, py::dict> mesh(const py::array& points, std::optional<int> threads,
                                    std::optional<std::uint64_t> memory, std::uint64_t tile_points,
                                    bool no_stats, const MesherArgs& mesher) {
  const auto start = std::chrono::steady_clock::now();
  g2s::PointCloud cloud = cloud_from(points);
  const std::uint64_t rows = cloud.size();
  const std::vector<g2s::Index> row_of = drop_non_finite(cloud);
  const g2s::PipelineOptions options = pipeline_options(mesher, threads.value_or(0));
  auto result = std::make_unique<g2s::PipelineMesh>();
  g2s::MeshStats stats;
  {
    py::gil_scoped_release released;
    // Tiles as `g2s mesh` cuts them for the same budget, grown in parallel and stitched.
    *result = g2s::mesh_cloud(cloud, options, tile_points, budget_of(memory));
    if (!no_stats && !result->triangles.empty()) {
      stats = g2s::compute_stats({cloud.xyz, result->triangles}, &cloud);
    }
    for (g2s::Triangle& t : result->triangles) {
      if (!row_of.empty()) t = {row_of[t[0]], row_of[t[1]], row_of[t[2]]};
    }
  }
  if (result->triangles.empty()) {
    throw_no_surface("points", cloud, result->report.points, rows - cloud.size());
  }
  py::dict summary = report_dict(*result);
  summary["non_finite"] = rows - cloud.size();
  summary["seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!no_stats) summary["stats"] = parse_json(g2s::stats_to_json(stats));
  // The triangles leave as a numpy view of the library's vector, owned by a capsule: no copy.
  auto* triangles = new std::vector<g2s::Triangle>(std::move(result->triangles));
  const py::capsule owner(triangles,
                          [](void* p) { delete static_cast<std::vector<g2s::Triangle>*>(p); });
  const py::array out(py::dtype::of<std::uint32_t>(),
                      {static_cast<py::ssize_t>(triangles->size()), py::ssize_t{3}},
                      reinterpret_cast<const std::uint32_t*>(triangles->data()), owner);
  return {out, summary};
}

py::dict mesh_file(const std::filesystem::path& input, const std::filesystem::path& output,
                   std::optional<int> threads, std::optional<std::uint64_t> memory,
                   std::uint64_t tile_points,
                   const std::optional<std::filesystem::path>& keep_store, bool compress,
                   bool ascii, bool no_stats, const MesherArgs& mesher) {
  py::gil_scoped_release released;
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<g2s::TemporaryPath> temporary;
  std::filesystem::path store_path = keep_store.value_or(std::filesystem::path());
  if (store_path.empty()) {
    temporary = std::make_unique<g2s::TemporaryPath>(
        output.parent_path() /
        ("." + output.filename().string() + ".store-" + std::to_string(getpid())));
    store_path = temporary->path();
  }
  const std::uint64_t budget = budget_of(memory);
  g2s::PipelineOptions options = pipeline_options(mesher, threads.value_or(0));
  const std::uint64_t planned_tile =
      tile_points > 0 ? tile_points : g2s::plan_memory(budget, options.threads).tile_points;
  // A kept store made from this input for this plan is reused, as `g2s mesh --keep-store` does;
  // a file there that is no tile store is refused rather than overwritten.
  std::string why;
  const bool first_cut_made =
      !temporary && g2s::kept_store_matches(store_path, input, planned_tile, why);
  // Cut as g2s mesh cuts for the same budget: the same tiles, so the same mesh.
  g2s::TileStoreOptions tiling;
  tiling.tile_points = tile_points;
  tiling.compress = compress;
  const g2s::BudgetTiling tiled =
      g2s::tile_for_budget(input, store_path, budget, options, tiling, first_cut_made);
  const g2s::TileStore store(store_path);
  const g2s::ReadReport& read = store.input_report();
  options.tiles_in_flight = tiled.plan.tiles_in_flight;
  // The defects are counted as the mesh streams out, as `g2s mesh` counts them; only where that
  // count could not be exact is the file read back, if that fits in the budget.
  const g2s::MeshFormat format = g2s::mesh_format_for(output, ascii);
  const bool stl = format != g2s::MeshFormat::ply_binary;
  g2s::MeshStreamWriter writer(output, format);
  g2s::StreamStats counter(writer, stl, !stl);
  const g2s::PipelineSummary summary =
      g2s::mesh_tiles(store, options, no_stats ? static_cast<g2s::MeshSink&>(writer) : counter);
  if (summary.triangles == 0) {
    g2s::PointCloud cloud;
    for (std::size_t t = 0; t < store.tiles().size(); ++t) {
      const g2s::TilePoints points = store.load(t);
      cloud.xyz.insert(cloud.xyz.end(), points.xyz.begin(), points.xyz.end());
    }
    throw_no_surface(input.string(), cloud, summary.report.points, read.non_finite);
  }
  const g2s::WrittenMeshStats written =
      no_stats ? g2s::WrittenMeshStats{}
               : g2s::measure_written_mesh(counter, output, stl, writer.float_rounding(),
                                           summary.report.spacing, summary.triangles, budget);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  py::gil_scoped_acquire acquired;
  py::dict d = report_dict(summary);
  d["input"] = input.string();
  d["output"] = output.string();
  d["format"] = read.format;
  d["non_finite"] = read.non_finite;
  d["seconds"] = seconds;
  if (written.stats) d["stats"] = parse_json(g2s::stats_to_json(*written.stats));
  d["stats_in_stride"] = written.in_stride;
  return d;
}

py::dict stats(const py::array& points, const py::array& triangles) {
  const g2s::PointCloud cloud = cloud_from(points);
  const auto t =
      py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(triangles);
  if (!t || t.ndim() != 2 || t.shape(1) != 3)
    throw py::value_error("triangles: expected an (M, 3) integer array");
  g2s::IndexedMesh mesh{cloud.xyz, {}};
  mesh.triangles.resize(static_cast<std::size_t>(t.shape(0)));
  const std::int64_t* idx = t.data();
  for (std::size_t i = 0; i < 3 * mesh.triangles.size(); ++i) {
    if (idx[i] < 0 || static_cast<std::uint64_t>(idx[i]) >= cloud.size()) {
      throw g2s::Error(g2s::Exit::bad_input, "triangles: index " + std::to_string(idx[i]) +
                                                 " of triangle " + std::to_string(i / 3) +
                                                 " is not a point (there are " +
                                                 std::to_string(cloud.size()) + ")");
    }
    mesh.triangles[i / 3][i % 3] = static_cast<g2s::Index>(idx[i]);
  }
  std::string json;
  {
    py::gil_scoped_release released;
    json = g2s::stats_to_json(g2s::compute_stats(mesh, &cloud));
  }
  return parse_json(json);
}

}  // namespace

PYBIND11_MODULE(_g2s, m) {
  m.doc() = "G2S meshing of point clouds (the g2s library)";
  py::object base = py::reinterpret_borrow<py::object>(PyExc_RuntimeError);
  static py::exception<g2s::Error> error(m, "Error", base.ptr());
  static py::exception<g2s::Error> usage_error(m, "UsageError", error.ptr());
  static py::exception<g2s::Error> input_error(m, "InputError", error.ptr());
  static py::exception<g2s::Error> output_error(m, "OutputError", error.ptr());
  static py::exception<g2s::Error> no_surface_error(m, "NoSurfaceError", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const g2s::Error& e) {
      py::object type = error;
      switch (e.code()) {
        case g2s::Exit::usage:
          type = usage_error;
          break;
        case g2s::Exit::bad_input:
          type = input_error;
          break;
        case g2s::Exit::write_failed:
          type = output_error;
          break;
        case g2s::Exit::no_surface:
          type = no_surface_error;
          break;
        default:
          break;
      }
      py::object instance = type(e.what());
      instance.attr("exit_code") = static_cast<int>(e.code());
      PyErr_SetObject(type.ptr(), instance.ptr());
    }
  });

  const auto mesher_args = [](std::optional<std::vector<double>> radius_steps, int flatness_levels,
                              double max_fold, double max_radius, bool keep_gaps,
                              int max_hole_edges, int max_hole_rings, bool no_orient) {
    return MesherArgs{std::move(radius_steps), flatness_levels, max_fold, max_radius, keep_gaps,
                      max_hole_edges,          max_hole_rings,  no_orient};
  };
  m.def(
      "mesh",
      [mesher_args](const py::array& points, std::optional<int> threads,
                    std::optional<std::uint64_t> memory, std::uint64_t tile_points, bool no_stats,
                    std::optional<std::vector<double>> radius_steps, int flatness_levels,
                    double max_fold, double max_radius, bool keep_gaps, int max_hole_edges,
                    int max_hole_rings, bool no_orient) {
        return mesh(points, threads, memory, tile_points, no_stats,
                    mesher_args(std::move(radius_steps), flatness_levels, max_fold, max_radius,
                                keep_gaps, max_hole_edges, max_hole_rings, no_orient));
      },
      py::arg("points"), py::kw_only(), py::arg("threads") = py::none(),
      py::arg("memory") = py::none(), py::arg("tile_points") = 0, py::arg("no_stats") = false,
      py::arg("radius_steps") = py::none(), py::arg("flatness_levels") = 4,
      py::arg("max_fold") = 135.0, py::arg("max_radius") = 6.0, py::arg("keep_gaps") = false,
      py::arg("max_hole_edges") = 30, py::arg("max_hole_rings") = 3, py::arg("no_orient") = false);
  m.def(
      "mesh_file",
      [mesher_args](const std::filesystem::path& input, const std::filesystem::path& output,
                    std::optional<int> threads, std::optional<std::uint64_t> memory,
                    std::uint64_t tile_points, std::optional<std::filesystem::path> keep_store,
                    bool compress, bool ascii, bool no_stats,
                    std::optional<std::vector<double>> radius_steps, int flatness_levels,
                    double max_fold, double max_radius, bool keep_gaps, int max_hole_edges,
                    int max_hole_rings, bool no_orient) {
        return mesh_file(input, output, threads, memory, tile_points, keep_store, compress, ascii,
                         no_stats,
                         mesher_args(std::move(radius_steps), flatness_levels, max_fold, max_radius,
                                     keep_gaps, max_hole_edges, max_hole_rings, no_orient));
      },
      py::arg("input"), py::arg("output"), py::kw_only(), py::arg("threads") = py::none(),
      py::arg("memory") = py::none(), py::arg("tile_points") = 0,
      py::arg("keep_store") = py::none(), py::arg("compress") = false, py::arg("ascii") = false,
      py::arg("no_stats") = false, py::arg("radius_steps") = py::none(),
      py::arg("flatness_levels") = 4, py::arg("max_fold") = 135.0, py::arg("max_radius") = 6.0,
      py::arg("keep_gaps") = false, py::arg("max_hole_edges") = 30, py::arg("max_hole_rings") = 3,
      py::arg("no_orient") = false);
  m.def("stats", &stats, py::arg("points"), py::arg("triangles"));
}
