#!/usr/bin/env python3
"""Checks `g2s stats`' crossing counts against CGAL's Polygon_mesh_processing::self_intersections.

For every mesh, the pairs of crossing triangles that share no vertex must be the same number in
both (`crossing_pairs_no_shared_vertex` of `g2s stats --json`, `pairs_no_shared_vertex` of the
peer driver bench/peers/cgal_self_intersections.cpp). Pairs that share a vertex or an edge are
shown but not compared: CGAL judges them on its halfedge structure, whose vertices may have been
split to make a non-manifold soup a polygon mesh (docs/algorithm.md, "Mesh statistics").

The meshes are those given on the command line, plus, unless --no-scans, the meshes of the shared
scans made by `g2s mesh` and, where their drivers are built (-DG2S_BUILD_PEERS=ON, see
bench/peers/README.md), by PCL's greedy projection and Open3D's ball pivoting. Prints a Markdown
table; exit status 1 when any count differs, 2 when a tool is missing.

    bench/check_self_intersections.py [--g2s build/g2s] [--peers build-bench/bench/peers]
        [--data ../shared/data] [--work /tmp/g2s-check-si] [--scans a,b,...] [--no-scans] [MESH...]
"""
import argparse
import json
import os
import pathlib
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
DEFAULT_SCANS = [
    "raw-bunny",
    "open-lion-photogrammetry",
    "open-table-mug-stereo",
    "open-autzen-lidar",
    "open-bunny-scan-bun000",
]
# Meshers run on every scan: name, command (with {cloud} and {mesh}), driver file needed.
MESHERS = [
    ("g2s", "{g2s} mesh {cloud} -o {mesh} --quiet --no-stats", None),
    ("pcl-gp3", "{peers}/peer_pcl_gp3 {cloud} {mesh}", "peer_pcl_gp3"),
    ("open3d-bpa", "{peers}/peer_open3d_bpa {cloud} {mesh}", "peer_open3d_bpa"),
]


def run(command):
    started = time.monotonic()
    result = subprocess.run(command, capture_output=True, text=True, check=False)
    if result.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, command))} failed ({result.returncode}): "
                           f"{result.stderr.strip()}")
    return result.stdout, time.monotonic() - started


def measure(mesh, g2s, cgal):
    stats_out, g2s_seconds = run([g2s, "stats", mesh, "--json"])
    stats = json.loads(stats_out)
    cgal_out, cgal_seconds = run([cgal, mesh])
    peer = json.loads(cgal_out.strip().splitlines()[-1])
    return {
        "mesh": str(mesh),
        "triangles": stats["triangles"],
        "g2s_pairs": stats["crossing_pairs"],
        "g2s_no_shared": stats["crossing_pairs_no_shared_vertex"],
        "g2s_triangles_involved": stats["crossing_triangles"],
        "cgal_pairs": peer["pairs"],
        "cgal_no_shared": peer["pairs_no_shared_vertex"],
        "g2s_seconds": g2s_seconds,
        "cgal_seconds": cgal_seconds,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("meshes", nargs="*", help="extra meshes (STL, PLY) to check")
    parser.add_argument("--g2s", default=str(ROOT / "build" / "g2s"))
    parser.add_argument("--peers", default=str(ROOT / "build-bench" / "bench" / "peers"))
    parser.add_argument("--data", default=os.environ.get("G2S_DATA_DIR",
                                                         str(ROOT.parent / "shared" / "data")))
    parser.add_argument("--work", default="/tmp/g2s-check-self-intersections")
    parser.add_argument("--scans", default=",".join(DEFAULT_SCANS))
    parser.add_argument("--no-scans", action="store_true")
    args = parser.parse_args()

    cgal = pathlib.Path(args.peers) / "peer_cgal_self_intersections"
    for tool in (pathlib.Path(args.g2s), cgal):
        if not tool.exists():
            print(f"check_self_intersections: {tool} not found (build it first)", file=sys.stderr)
            return 2
    work = pathlib.Path(args.work)
    work.mkdir(parents=True, exist_ok=True)

    meshes = [pathlib.Path(m) for m in args.meshes]
    if not args.no_scans:
        for scan in args.scans.split(","):
            cloud = pathlib.Path(args.data) / f"{scan}.ply"
            for name, template, driver in MESHERS:
                if driver and not (pathlib.Path(args.peers) / driver).exists():
                    continue
                mesh = work / f"{scan}.{name}.stl"
                if not mesh.exists() or mesh.stat().st_mtime < cloud.stat().st_mtime:
                    command = template.format(g2s=args.g2s, peers=args.peers, cloud=cloud,
                                              mesh=mesh).split()
                    try:
                        run(command)
                    except RuntimeError as error:
                        print(f"skipped: {error}", file=sys.stderr)
                        continue
                meshes.append(mesh)

    print("| mesh | triangles | g2s pairs | g2s pairs, no shared vertex | CGAL pairs | "
          "CGAL pairs, no shared vertex | agree | g2s stats s | CGAL s |")
    print("|---|---:|---:|---:|---:|---:|---|---:|---:|")
    mismatches = 0
    for mesh in meshes:
        r = measure(mesh, args.g2s, cgal)
        agree = r["g2s_no_shared"] == r["cgal_no_shared"]
        mismatches += 0 if agree else 1
        print(f"| {mesh.name} | {r['triangles']:,} | {r['g2s_pairs']:,} | {r['g2s_no_shared']:,} "
              f"| {r['cgal_pairs']:,} | {r['cgal_no_shared']:,} | {'yes' if agree else 'NO'} "
              f"| {r['g2s_seconds']:.1f} | {r['cgal_seconds']:.1f} |", flush=True)
    return 1 if mismatches else 0


if __name__ == "__main__":
    sys.exit(main())
