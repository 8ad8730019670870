#!/usr/bin/env python3
"""Bounded-memory benchmark of `g2s mesh --memory` (issue 4): synthetic tori of growing size
meshed under one budget; peak resident memory as GNU time reports it (maximum resident set,
which counts the mapped pages of the input and the tile store that are resident).

    bench/memory.py [--points 10M,40M] [--memory 512M] [--threads 2] [--runs 1] [--stats]

For each size: `g2s synth torus`, then `g2s mesh --memory M --threads T --json` under
/usr/bin/time -v; with --stats also `g2s stats` on the mesh (which needs far more memory than the
budget for large meshes: it holds the whole mesh). Prints a Markdown table and writes
bench/results/<UTC date>-<commit>-memory.{json,md}. The peaks of the largest and the smallest
size should differ by less than 15%, and all stay under the budget plus 15%.
Python 3 standard library only; needs GNU time.
"""

import argparse
import datetime
import json
import platform
import re
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "bench"))
from run import count  # noqa: E402  (the same '10M'-style counts as bench/run.py)


def run_timed(command):
    """Runs under GNU time; returns (stdout, peak RSS in MB, wall seconds)."""
    result = subprocess.run(["/usr/bin/time", "-v", *command], capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"bench/memory.py: {' '.join(command)} failed:\n{result.stderr[-2000:]}")
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", result.stderr)
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", result.stderr)
    seconds = 0.0
    for part in wall.group(1).split(":"):
        seconds = 60 * seconds + float(part)
    return result.stdout, int(rss.group(1)) / 1024, seconds


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--build", default="build", help="build folder with g2s (default: build)")
    p.add_argument("--points", default="10M,40M",
                   type=lambda s: [count(x) for x in s.split(",")],
                   help="torus sizes (default 10M,40M)")
    p.add_argument("--memory", default="512M", help="the budget passed to --memory (default 512M)")
    p.add_argument("--threads", type=int, default=2, help="threads (default 2)")
    p.add_argument("--runs", type=int, default=1, help="runs per size; the median peak is kept")
    p.add_argument("--stats", action="store_true", help="also measure each mesh with g2s stats")
    p.add_argument("--work", help="folder for the clouds and meshes (default: a temporary one)")
    p.add_argument("--out", default="bench/results", help="result folder")
    args = p.parse_args()
    g2s = (REPO / args.build / "g2s").resolve()
    if not g2s.exists():
        sys.exit(f"bench/memory.py: no {g2s}; build first (scripts/test.sh builds it)")
    size = re.fullmatch(r"([0-9]*\.?[0-9]+)([kKmMgG]?)[bB]?", args.memory)
    if not size:
        sys.exit(f"bench/memory.py: --memory {args.memory}: expected a size like 512M or 2G")
    budget_mb = float(size.group(1)) * {"": 1 / 1048576, "k": 1 / 1024, "m": 1, "g": 1024}[
        size.group(2).lower()]
    work = Path(args.work) if args.work else Path(tempfile.mkdtemp(prefix="g2s-memory-"))
    work.mkdir(parents=True, exist_ok=True)
    rows = []
    for points in args.points:
        cloud = work / f"torus-{points}.ply"
        if not cloud.exists():
            subprocess.run([str(g2s), "synth", "torus", "-n", str(points), "-o", str(cloud)],
                           check=True, capture_output=True)
        mesh = work / f"torus-{points}.stl"
        peaks, walls, summary = [], [], {}
        for _ in range(args.runs):
            out, peak, wall = run_timed([str(g2s), "mesh", str(cloud), "-o", str(mesh),
                                         "--memory", args.memory, "--threads",
                                         str(args.threads), "--json", "--no-stats"])
            summary = json.loads(out)
            peaks.append(peak)
            walls.append(wall)
            print(f"{points:,} points: peak {peak:.0f} MB, {wall:.1f} s", file=sys.stderr)
        peaks.sort()
        walls.sort()
        row = {"points": points, "tiles": summary["tiles"], "triangles": summary["triangles"],
               "peak_rss_mb": peaks[len(peaks) // 2], "peak_rss_mb_all": peaks,
               "wall_s": walls[len(walls) // 2],
               "ktriangles_per_second": summary["triangles"] / walls[len(walls) // 2] / 1000,
               "peak_live_points": summary["peak_live_points"]}
        if args.stats:
            out = subprocess.run([str(g2s), "stats", str(mesh), "--json"], check=True,
                                 capture_output=True, text=True).stdout
            row["stats"] = json.loads(out)
        mesh.unlink(missing_ok=True)
        rows.append(row)
    spread = max(r["peak_rss_mb"] for r in rows) / min(r["peak_rss_mb"] for r in rows) - 1
    commit = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip() or "unknown"
    cpu = "unknown"
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break
    now = datetime.datetime.now(datetime.timezone.utc)
    lines = [f"g2s {commit}, {now:%Y-%m-%dT%H:%M:%SZ}; {platform.machine()}, {cpu}; "
             f"`g2s mesh --memory {args.memory} --threads {args.threads}`, {args.runs} run(s)",
             "",
             "| torus points | tiles | triangles | wall s | k-triangles/s | peak RSS MB | "
             "peak live points | defects (nm edges / nm vertices / conflicts / boundary) |",
             "|---:|---:|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        s = r.get("stats")
        defects = (f"{s['non_manifold_edges']} / {s['non_manifold_vertices']} / "
                   f"{s['orientation_conflicts']} / {s['boundary_edges']}" if s else "not measured")
        lines.append(f"| {r['points']:,} | {r['tiles']} | {r['triangles']:,} | {r['wall_s']:.1f} "
                     f"| {r['ktriangles_per_second']:.0f} | {r['peak_rss_mb']:.0f} | "
                     f"{r['peak_live_points']:,} | {defects} |")
    lines += ["", f"Largest peak over smallest: +{100 * spread:.1f}% (target: under 15%); budget "
                  f"{budget_mb:.0f} MB, largest peak {max(r['peak_rss_mb'] for r in rows):.0f} MB."]
    text = "\n".join(lines) + "\n"
    print(text)
    out_dir = REPO / args.out
    out_dir.mkdir(parents=True, exist_ok=True)
    stem = out_dir / f"{now:%Y-%m-%d}-{commit}-memory"
    stem.with_suffix(".md").write_text(text)
    stem.with_suffix(".json").write_text(json.dumps(
        {"commit": commit, "date": now.isoformat(), "cpu": cpu, "memory": args.memory,
         "threads": args.threads, "runs": args.runs, "rows": rows, "spread": spread}, indent=1))


if __name__ == "__main__":
    main()
