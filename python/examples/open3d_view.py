#!/usr/bin/env python3
"""Meshes a point cloud with g2s and hands the result to Open3D (python3-open3d): the points are
the mesh's vertices, g2s's triangles index them. Open3D checks the mesh and saves it (any format
it writes); with --show, it opens a window on it.

    python3 python/examples/open3d_view.py CLOUD.ply OUT.ply [--show]

(Open3D's offscreen renderer needs EGL, which Debian's build lacks on a headless machine; there,
`g2s render OUT.ply -o OUT.png` draws the mesh.)

The cloud is read with Open3D here (any format it reads); g2s.mesh_file reads PLY, LAS and XYZ
itself, out of core.
"""
import argparse

import numpy as np
import open3d as o3d

import g2s


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("cloud")
    parser.add_argument("output")
    parser.add_argument("--show", action="store_true", help="open a window on the mesh")
    args = parser.parse_args()

    points = np.asarray(o3d.io.read_point_cloud(args.cloud).points)  # (N, 3) float64, no copy
    triangles, summary = g2s.mesh(points)
    print(f"{summary['points']} points -> {summary['triangles']} triangles in "
          f"{summary['seconds']:.2f} s; non-manifold edges {summary['stats']['non_manifold_edges']}, "
          f"boundary edges {summary['stats']['boundary_edges']}")

    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(points),
                                     o3d.utility.Vector3iVector(triangles.astype(np.int32)))
    mesh.remove_unreferenced_vertices()
    mesh.compute_vertex_normals()
    print(f"Open3D: edge manifold {mesh.is_edge_manifold()}, "
          f"vertex manifold {mesh.is_vertex_manifold()}, watertight {mesh.is_watertight()}")
    o3d.io.write_triangle_mesh(args.output, mesh)
    if args.show:
        o3d.visualization.draw_geometries([mesh])

if __name__ == "__main__":
    main()
