"""g2s: manifold triangle meshes from point clouds (G2S mesh growing), from Python.

    triangles, summary = g2s.mesh(points)            # (N, 3) float32/float64 array in memory
    summary = g2s.mesh_file("scan.las", "mesh.ply")  # out of core, file to file, like `g2s mesh`
    counts = g2s.stats(points, triangles)            # what `g2s stats` measures

The mesh interpolates: its vertices are the input points, so `triangles` is an (M, 3) uint32
array of indices into `points`. Options are the CLI's (`--max-fold 120` is `max_fold=120`),
`memory` is a byte count or a size like "512M" or "4G". Errors raise g2s.Error, or its subclass
for the CLI's exit code (UsageError 2, InputError 3, OutputError 4, NoSurfaceError 5), with the
CLI's message; `exit_code` holds the code.
"""
import re as _re

from . import _g2s
from ._g2s import Error, InputError, NoSurfaceError, OutputError, UsageError

__all__ = ["mesh", "mesh_file", "stats", "Error", "UsageError", "InputError", "OutputError",
           "NoSurfaceError"]

_UNITS = {"": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}


def _bytes(memory):
    """None, a byte count, or "512M"/"4G"/"1.5G" (as `g2s mesh --memory`) -> bytes or None."""
    if memory is None or isinstance(memory, int):
        return memory
    match = _re.fullmatch(r"\s*([0-9]*\.?[0-9]+)\s*([kKmMgGtT]?)[bB]?\s*", str(memory))
    if not match:
        raise UsageError(f"memory: expected a size such as 512M or 4G, not {memory!r}")
    return int(float(match.group(1)) * _UNITS[match.group(2).upper()])


def _mesher(radius_steps, flatness_levels, max_fold, max_radius, max_hole_edges, max_hole_rings):
    """The CLI's ranges for the mesher's options."""
    if radius_steps is not None and not 1 <= len(radius_steps) <= 16:
        raise UsageError("radius_steps: expected 1 to 16 values")
    for name, value, lo, hi in (("flatness_levels", flatness_levels, 1, 64),
                                ("max_fold", max_fold, 10.0, 179.0),
                                ("max_radius", max_radius, 1.0, 1000.0),
                                ("max_hole_edges", max_hole_edges, 0, 100),
                                ("max_hole_rings", max_hole_rings, 0, 10)):
        if not lo <= value <= hi:
            raise UsageError(f"{name}: {value} is not in [{lo}, {hi}]")


def mesh(points, *, threads=None, memory=None, tile_points=0, no_stats=False, radius_steps=None,
         flatness_levels=4, max_fold=135.0, max_radius=6.0, keep_gaps=False, max_hole_edges=30,
         max_hole_rings=3, no_orient=False):
    """Meshes an (N, 3) float32 or float64 array in memory, tiled and in parallel as `g2s mesh`
    (`memory` sets the tile size, default half the RAM; `threads` default all cores). The GIL is
    released while meshing. Returns (triangles, summary): an (M, 3) uint32 array of indices into
    `points`, and a dict of counts (points, triangles, tiles, spacing, seconds, ...) with the
    mesh's defects under "stats" (`g2s stats --points`' counts, crossings and coverage included;
    left out with no_stats, which saves their time). Points with NaN or Inf coordinates are never
    used. Raises NoSurfaceError when the points form no surface, with the CLI's reason."""
    _mesher(radius_steps, flatness_levels, max_fold, max_radius, max_hole_edges, max_hole_rings)
    return _g2s.mesh(points, threads=threads, memory=_bytes(memory), tile_points=tile_points,
                     no_stats=no_stats, radius_steps=radius_steps, flatness_levels=flatness_levels,
                     max_fold=max_fold, max_radius=max_radius, keep_gaps=keep_gaps,
                     max_hole_edges=max_hole_edges, max_hole_rings=max_hole_rings,
                     no_orient=no_orient)


def mesh_file(input, output, *, threads=None, memory=None, tile_points=0, keep_store=None,
              compress=False, ascii=False, no_stats=False, radius_steps=None, flatness_levels=4,
              max_fold=135.0, max_radius=6.0, keep_gaps=False, max_hole_edges=30, max_hole_rings=3,
              no_orient=False):
    """`g2s mesh INPUT -o OUTPUT` in this process: the cloud (PLY, LAS, XYZ) is cut into a tile
    store beside the output (or at keep_store), grown and stitched within `memory`, and the
    mesh streamed to OUTPUT (.ply, or .stl; ascii=True for ASCII STL). Returns the summary dict
    of `g2s mesh --json`; "stats" holds the defects counted as the mesh streamed out
    ("stats_in_stride" true; the crossing pairs are left to `g2s stats`), or, where that count
    could not be exact, as read back; it is left out when no_stats or when reading the mesh back
    would not fit in `memory`."""
    _mesher(radius_steps, flatness_levels, max_fold, max_radius, max_hole_edges, max_hole_rings)
    return _g2s.mesh_file(str(input), str(output), threads=threads, memory=_bytes(memory),
                          tile_points=tile_points,
                          keep_store=None if keep_store is None else str(keep_store),
                          compress=compress, ascii=ascii, no_stats=no_stats,
                          radius_steps=radius_steps, flatness_levels=flatness_levels,
                          max_fold=max_fold, max_radius=max_radius, keep_gaps=keep_gaps,
                          max_hole_edges=max_hole_edges, max_hole_rings=max_hole_rings,
                          no_orient=no_orient)


def stats(points, triangles):
    """Measures the mesh `triangles` (an (M, 3) integer array of indices into the (N, 3) array
    `points`) as `g2s stats MESH --points CLOUD` does: a dict of triangles, vertices, defects
    (non-manifold edges and vertices, orientation conflicts, duplicates, degenerate triangles),
    boundary edges, holes, components, and the coverage of `points`."""
    return _g2s.stats(points, triangles)
