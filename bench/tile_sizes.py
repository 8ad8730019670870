#!/usr/bin/env python3
"""Tile size against thread count: `g2s mesh --json --no-stats` on each cloud for every
--tile-points and --threads given, runs alternating (size and thread count change every run, so
a load change on a shared machine hits all settings alike). Prints one JSON line per run (with
`uptime`'s load) and, at the end, the median seconds per setting and the speed-up of the most
threads over 1.

    bench/tile_sizes.py --g2s build/g2s --sizes 0 262144 131072 --threads 1 2 --runs 3 CLOUD...

Size 0 is the default (no --tile-points); --stats keeps the defect summary. Each run records
the per-stage wall and CPU seconds of `--json` ("stages"). Python 3 standard library only.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile


STATS = False


def load():
    return os.getloadavg()[0]


def run(g2s, cloud, size, threads, out):
    cmd = [g2s, "mesh", cloud, "-o", out, "--threads", str(threads), "--json"]
    if not STATS:
        cmd.append("--no-stats")
    if size:
        cmd += ["--tile-points", str(size)]
    before = load()
    done = subprocess.run(cmd, check=True, capture_output=True, text=True)
    summary = json.loads(done.stdout)
    return {"cloud": os.path.basename(cloud), "tile_points": size, "threads": threads,
            "tiles": summary["tiles"], "triangles": summary["triangles"],
            "seconds": summary["seconds"], "seconds_stitch": summary["seconds_stitch"],
            "seconds_grow": summary["seconds_grow"], "peak_rss_mb": summary["peak_rss_mb"],
            "cpu": summary.get("stages"),
            "load_before": round(before, 2), "load_after": round(load(), 2)}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--g2s", default="build/g2s")
    parser.add_argument("--sizes", type=int, nargs="+", default=[0])
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--stats", action="store_true", help="with the defect summary")
    parser.add_argument("clouds", nargs="+")
    args = parser.parse_args()
    global STATS
    STATS = args.stats
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        out = os.path.join(folder, "mesh.stl")
        for cloud in args.clouds:
            for _ in range(args.runs):
                for size in args.sizes:
                    for threads in args.threads:
                        row = run(args.g2s, cloud, size, threads, out)
                        rows.append(row)
                        print(json.dumps(row), flush=True)
    print("# medians: cloud, tile_points, tiles, then per thread count: seconds; speed-up")
    for cloud in args.clouds:
        name = os.path.basename(cloud)
        for size in args.sizes:
            medians = {}
            tiles = 0
            for threads in args.threads:
                times = [r["seconds"] for r in rows
                         if r["cloud"] == name and r["tile_points"] == size
                         and r["threads"] == threads]
                tiles = [r["tiles"] for r in rows
                         if r["cloud"] == name and r["tile_points"] == size][0]
                medians[threads] = statistics.median(times)
            first, last = min(args.threads), max(args.threads)
            cells = " ".join(f"{t}:{medians[t]:.3f}" for t in args.threads)
            print(f"# {name} {size} tiles={tiles} {cells} "
                  f"speedup={medians[first] / medians[last]:.2f}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
