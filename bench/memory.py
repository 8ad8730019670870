#!/usr/bin/env python3
"""Bounded-memory benchmark of `g2s mesh --memory` (issues 4 and 21): synthetic clouds of growing
size meshed under one budget; peak resident memory as GNU time reports it (maximum resident set,
which counts the mapped pages of the input and the tile store that are resident).

    bench/memory.py [--points 10M,40M,160M] [--shape terrain] [--noise 0.1] [--outliers 0.001]
                    [--memory 1G] [--threads 2] [--runs 1] [--stats] [--work DIR]

The default cloud has the features of a real scan: an open surface (terrain: a height field with
open borders), Gaussian noise (sigma in mean spacings) and outliers (uniform in its box, which
also makes the density uneven); `--shape torus --noise 0 --outliers 0` gives the earlier runs'
closed torus. For each size: `g2s synth`, then `g2s mesh --memory M --threads T --json
--keep-store` under /usr/bin/time -v (the store is made afresh each run, so tiling is timed);
with --stats also `g2s stats` on the mesh (which needs far more memory than the budget for large
meshes: it holds the whole mesh). Records peak RSS, wall time, k-triangles/s, the sizes of the
cloud, the tile store and the output, prints a Markdown table with an extrapolation to 1B points,
and writes bench/results/<UTC date>-<commit>-memory.{json,md,png} (the chart with gnuplot, as
bench/run.py draws its charts). The peaks of the largest and the smallest size should differ by
less than 15%, all stay under the budget plus 15%, and the throughputs differ by less than 20%.
`--with RESULT.json` adds the sizes of earlier runs of the same settings to the table, the
comparisons and the chart (a size measured again, later or by this run, replaces the earlier
row; `--points '' --with A.json --with B.json` only combines), so a long size can be measured
on its own.
Python 3 standard library only; needs GNU time.
"""

import argparse
import datetime
import json
import platform
import re
import subprocess
import sys
import shutil
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "bench"))
from run import count, gnuplot  # noqa: E402  (the same '10M'-style counts and charts as bench/run.py)


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


def plot_scale(rows, png, title, tmp):
    """Throughput, peak RSS, time per million triangles and disk against points."""
    data = tmp / "scale.dat"
    data.write_text("".join(
        f"{r['points']} {r['ktriangles_per_second']} {r['peak_rss_mb']} "
        f"{1e6 * r['wall_s'] / r['triangles']} {r['store_bytes'] / 1e9} {r['output_bytes'] / 1e9}\n"
        for r in rows))
    return gnuplot(f"""set terminal pngcairo size 1400,400 font ",10"
set output "{png}"
set multiplot layout 1,4 title "{title}"
set logscale x
set xlabel "points"
set grid
set format x "%.0s%c"
set key off
set yrange [0:*]
set title "throughput (k triangles/s)"
plot "{data}" using 1:2 with linespoints pt 7 lw 2
set title "peak RSS (MB)"
plot "{data}" using 1:3 with linespoints pt 7 lw 2 lc 2
set title "wall seconds per million triangles"
plot "{data}" using 1:4 with linespoints pt 7 lw 2 lc 3
set title "disk (GB): tile store, output"
set key top left
set logscale y
set yrange [*:*]
plot "{data}" using 1:5 with linespoints pt 7 lw 2 lc 4 title "store", \\
     "{data}" using 1:6 with linespoints pt 7 lw 2 lc 6 title "output"
unset multiplot
""", tmp)


def extrapolate(rows, target=10**9):
    """1B points from the largest run: time and disk per point, memory flat but for the live band
    (about 100 bytes a live point, growing with the square root of the points)."""
    big = rows[-1]
    scale = target / big["points"]
    band_mb = big["peak_live_points"] * (scale ** 0.5 - 1) * 100 / 1e6
    return {"points": target, "from_points": big["points"],
            "triangles": big["triangles"] * scale, "wall_s": big["wall_s"] * scale,
            "cloud_gb": big["cloud_bytes"] * scale / 1e9,
            "store_gb": big["store_bytes"] * scale / 1e9,
            "output_gb": big["output_bytes"] * scale / 1e9,
            "peak_rss_mb": big["peak_rss_mb"] + band_mb, "live_band_mb": band_mb}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--build", default="build", help="build folder with g2s (default: build)")
    p.add_argument("--points", default="10M,40M,160M",
                   type=lambda s: [count(x) for x in s.split(",") if x.strip()],
                   help="cloud sizes (default 10M,40M,160M; empty with --with to only combine)")
    p.add_argument("--shape", default="terrain", help="g2s synth shape (default terrain)")
    p.add_argument("--noise", type=float, default=0.1,
                   help="g2s synth --noise, sigma in mean spacings (default 0.1)")
    p.add_argument("--outliers", type=float, default=0.001,
                   help="g2s synth --outliers, a fraction of the points (default 0.001)")
    p.add_argument("--memory", default="1G", help="the budget passed to --memory (default 1G)")
    p.add_argument("--threads", type=int, default=2, help="threads (default 2)")
    p.add_argument("--runs", type=int, default=1, help="runs per size; the median peak is kept")
    p.add_argument("--stats", action="store_true", help="also measure each mesh with g2s stats")
    p.add_argument("--work", help="folder for the clouds and meshes (default: a temporary one)")
    p.add_argument("--keep-clouds", action="store_true",
                   help="keep each cloud in --work for the next run (default: delete it)")
    p.add_argument("--out", default="bench/results", help="result folder")
    p.add_argument("--with", dest="earlier", metavar="RESULT.json", action="append", default=[],
                   help="an earlier result of this script with the same cloud and budget: its "
                        "sizes join this run's table, comparisons and chart (may be repeated)")
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
    cloud_name = f"{args.shape}-noise{args.noise:g}-outliers{args.outliers:g}"
    rows = []
    for result in args.earlier:
        earlier = json.loads(Path(result).read_text())
        same = [(earlier.get(k), getattr(args, k)) for k in ("shape", "noise", "outliers", "memory",
                                                             "threads")]
        if any(a != b for a, b in same):
            sys.exit(f"bench/memory.py: {result} was measured with other settings: {same}")
        # A size measured again (in a later file, or by this run) replaces the earlier row.
        rows = [r for r in rows if r["points"] not in {e["points"] for e in earlier["rows"]}]
        rows += [dict(r, commit=earlier["commit"], date=earlier["date"]) for r in earlier["rows"]]
    rows = [r for r in rows if r["points"] not in args.points]
    if not args.points and not rows:
        sys.exit("bench/memory.py: nothing to measure (--points) or combine (--with)")
    for points in args.points:
        cloud = work / f"{cloud_name}-{points}.ply"
        if not cloud.exists():
            subprocess.run([str(g2s), "synth", args.shape, "-n", str(points), "--noise",
                            str(args.noise), "--outliers", str(args.outliers), "-o", str(cloud)],
                           check=True, capture_output=True)
        mesh = work / f"{cloud_name}-{points}.stl"
        store = work / f"{cloud_name}-{points}.store"
        peaks, walls, summary = [], [], {}
        for _ in range(args.runs):
            store.unlink(missing_ok=True)
            out, peak, wall = run_timed([str(g2s), "mesh", str(cloud), "-o", str(mesh),
                                         "--memory", args.memory, "--threads",
                                         str(args.threads), "--keep-store", str(store),
                                         "--json", "--no-stats"])
            summary = json.loads(out)
            peaks.append(peak)
            walls.append(wall)
            print(f"{points:,} points: peak {peak:.0f} MB, {wall:.1f} s", file=sys.stderr)
        peaks.sort()
        walls.sort()
        row = {"points": points, "cloud_points": summary["points"], "tiles": summary["tiles"],
               "triangles": summary["triangles"],
               "peak_rss_mb": peaks[len(peaks) // 2], "peak_rss_mb_all": peaks,
               "wall_s": walls[len(walls) // 2],
               "ktriangles_per_second": summary["triangles"] / walls[len(walls) // 2] / 1000,
               "peak_live_points": summary["peak_live_points"],
               "cloud_bytes": cloud.stat().st_size, "store_bytes": store.stat().st_size,
               "output_bytes": mesh.stat().st_size,
               "load_average_after": Path("/proc/loadavg").read_text().split()[:3]}
        if args.stats:
            out = subprocess.run([str(g2s), "stats", str(mesh), "--json"], check=True,
                                 capture_output=True, text=True).stdout
            row["stats"] = json.loads(out)
        mesh.unlink(missing_ok=True)
        store.unlink(missing_ok=True)
        if not args.keep_clouds:
            cloud.unlink(missing_ok=True)
        rows.append(row)
    rows.sort(key=lambda r: r["points"])
    spread = max(r["peak_rss_mb"] for r in rows) / min(r["peak_rss_mb"] for r in rows) - 1
    first, last = rows[0], rows[-1]
    rss_change = last["peak_rss_mb"] / first["peak_rss_mb"] - 1
    speed_change = last["ktriangles_per_second"] / first["ktriangles_per_second"] - 1
    guess = extrapolate(rows)
    commit = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip() or "unknown"
    cpu = "unknown"
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break
    now = datetime.datetime.now(datetime.timezone.utc)
    for r in rows:
        r.setdefault("commit", commit)
        r.setdefault("date", now.isoformat())
    cloud_text = (f"`g2s synth {args.shape} --noise {args.noise:g} --outliers {args.outliers:g}`")
    lines = [f"g2s {commit}, {now:%Y-%m-%dT%H:%M:%SZ}; {platform.machine()}, {cpu}; "
             f"{cloud_text}; `g2s mesh --memory {args.memory} --threads {args.threads}`, "
             f"{args.runs} run(s)",
             "",
             "Measured" + (" (rows of " + ", ".join(f"{Path(f).name}" for f in args.earlier) +
                           " combined with this run)" if args.earlier else "") + ":",
             "",
             "| points | tiles | triangles | wall s | k-triangles/s | s per M triangles | "
             "peak RSS MB | peak live points | cloud GB | tile store GB | output GB | "
             "defects (nm edges / nm vertices / conflicts / boundary) |",
             "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        s = r.get("stats")
        defects = (f"{s['non_manifold_edges']} / {s['non_manifold_vertices']} / "
                   f"{s['orientation_conflicts']} / {s['boundary_edges']}" if s else "not measured")
        lines.append(f"| {r['points']:,} | {r['tiles']} | {r['triangles']:,} | {r['wall_s']:.1f} "
                     f"| {r['ktriangles_per_second']:.0f} | "
                     f"{1e6 * r['wall_s'] / r['triangles']:.2f} | {r['peak_rss_mb']:.0f} | "
                     f"{r['peak_live_points']:,} | {r['cloud_bytes'] / 1e9:.2f} | "
                     f"{r['store_bytes'] / 1e9:.2f} | {r['output_bytes'] / 1e9:.2f} | {defects} |")
    lines += ["",
              f"Largest peak over smallest: +{100 * spread:.1f}% (target: under 15%); budget "
              f"{budget_mb:.0f} MB, largest peak {max(r['peak_rss_mb'] for r in rows):.0f} MB. "
              f"{last['points']:,} against {first['points']:,} points: peak RSS "
              f"{100 * rss_change:+.1f}% (target within 15%), throughput "
              f"{100 * speed_change:+.1f}% (target within 20%).",
              "",
              f"Extrapolated (not measured) to {guess['points']:,} points, per point from the "
              f"{guess['from_points']:,}-point run, on this machine and thread count: "
              f"{guess['triangles'] / 1e9:.2f}B triangles, {guess['wall_s'] / 3600:.1f} h, cloud "
              f"{guess['cloud_gb']:.0f} GB + tile store {guess['store_gb']:.0f} GB + output "
              f"{guess['output_gb']:.0f} GB on disk, peak RSS about {guess['peak_rss_mb']:.0f} MB "
              f"(the measured peak plus {guess['live_band_mb']:.0f} MB for the live band, "
              f"which grows with the square root of the points)."]
    commit_stem = f"{now:%Y-%m-%d}-{commit}-memory"
    out_dir = REPO / args.out
    out_dir.mkdir(parents=True, exist_ok=True)
    stem = out_dir / commit_stem
    png = out_dir / f"{commit_stem}.png"
    if shutil.which("gnuplot") and plot_scale(
            rows, png, f"g2s mesh --memory {args.memory} --threads {args.threads}, {cloud_text} "
            f"({cpu}, commit {commit})".replace("`", ""), work):
        lines += ["", f"![scaling past RAM]({png.name})"]
    else:
        print("gnuplot not found (bench/peers/install.sh installs it): no chart", file=sys.stderr)
    text = "\n".join(lines) + "\n"
    stem.with_suffix(".md").write_text(text)
    stem.with_suffix(".json").write_text(json.dumps(
        {"commit": commit, "date": now.isoformat(), "cpu": cpu, "memory": args.memory,
         "threads": args.threads, "runs": args.runs, "with": args.earlier, "shape": args.shape, "noise": args.noise,
         "outliers": args.outliers, "rows": rows, "spread": spread, "rss_change": rss_change,
         "throughput_change": speed_change, "extrapolated": guess}, indent=1))
    print(text)


if __name__ == "__main__":
    main()
