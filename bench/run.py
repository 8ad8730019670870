#!/usr/bin/env python3
"""End-to-end benchmark of g2s and its peers: the one entry point for every table and chart.

    bench/run.py [options] [CLOUD...]          (bench/run.py --help; bench/README.md)

Three parts, each optional:
  compare  every cloud meshed --runs times by g2s and by each peer driver (bench/peers/),
           alternating g2s and peers run by run; wall seconds, k-triangles/s, peak RSS (GNU time)
           and the `g2s stats --json` defects of each method's mesh; peers as ratios to g2s.
  scaling  g2s on synthetic tori of growing size (throughput, peak RSS against points) and on
           one cloud with growing --threads.
  plots    PNG charts of both with gnuplot.
Writes bench/results/<UTC date>-<commit>.json (everything, with the machine and the commit), the
Markdown tables in <stem>.md beside it (also printed on stdout) and <stem>-*.png.

Python 3 standard library only; needs GNU time (/usr/bin/time), coreutils `timeout` and, for the
charts, gnuplot (bench/peers/install.sh installs both).
"""

import argparse
import datetime
import json
import os
import platform
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
PEERS = {  # method -> executable in the peers build folder
    "cgal-afsr": "bench/peers/peer_cgal_afsr",
    "pcl-gp3": "bench/peers/peer_pcl_gp3",
    "open3d-bpa": "bench/peers/peer_open3d_bpa",
}
DEFECTS = ["non_manifold_edges", "non_manifold_vertices", "orientation_conflicts",
           "boundary_edges", "holes"]


def log(message):
    print(message, file=sys.stderr, flush=True)


def die(message):
    log(f"bench/run.py: {message}")
    sys.exit(2)


def count(text):
    """'500k', '2M', '0.1M', '20000' -> int."""
    match = re.fullmatch(r"([0-9]*\.?[0-9]+)([kKmMgG]?)", text.strip())
    if not match:
        raise argparse.ArgumentTypeError(f"expected a count like 500k, 2M or 20000, not '{text}'")
    scale = {"": 1, "k": 10**3, "m": 10**6, "g": 10**9}[match.group(2).lower()]
    return int(round(float(match.group(1)) * scale))


def count_list(text):
    return [count(t) for t in text.split(",") if t.strip()]


def int_list(text):
    try:
        values = [int(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected whole numbers separated by commas, not '{text}'")
    if not values or min(values) < 1:
        raise argparse.ArgumentTypeError(f"expected positive whole numbers, not '{text}'")
    return values


def label(points):
    """2000000 -> '2M', 100000 -> '0.1M', 50000 -> '50k'."""
    if points >= 100_000:
        return f"{points / 1e6:g}M"
    return f"{points / 1e3:g}k" if points >= 1000 else str(points)


def group(n):
    return f"{n:,}" if isinstance(n, int) else "—"


def parse_args():
    cores = os.cpu_count() or 1
    default_threads = [1] + [t for t in (2, 4, 8, 16, 32, 64) if t <= cores]
    p = argparse.ArgumentParser(
        prog="bench/run.py", formatter_class=argparse.RawDescriptionHelpFormatter,
        description=__doc__.split("\n\n")[1].strip() + "\n\nSee bench/README.md.")
    p.add_argument("clouds", nargs="*", metavar="CLOUD",
                   help="clouds for the comparison (PLY, XYZ). Default: every *.ply in "
                        "$G2S_DATA_DIR or ../shared/data, plus synthetic tori (--synthetic)")
    p.add_argument("--build", default="build", help="build folder with g2s (default: build)")
    p.add_argument("--peers-build", help="build folder with the peer drivers (configured with "
                   "-DG2S_BUILD_PEERS=ON; default: --build)")
    p.add_argument("--peers", default="all", help="comma-separated peers to run among "
                   f"{','.join(PEERS)}, 'all' (those built) or 'none' (default: all)")
    p.add_argument("--runs", type=int, default=3, help="runs per cloud and method (default 3)")
    p.add_argument("--threads", type=int, default=1, help="threads for every compared method: "
                   "g2s --threads N, OMP_NUM_THREADS=N for peers (default 1)")
    p.add_argument("--peer-timeout", type=float, default=600,
                   help="seconds before a peer run is stopped and recorded as a timeout; the "
                        "peer then skips larger clouds (default 600)")
    p.add_argument("--peer-memory-gb", type=float, default=8,
                   help="address-space limit of a peer run, GB (default 8; 0: none)")
    p.add_argument("--synthetic", type=count_list, default=count_list("1M,5M,20M"),
                   help="synthetic torus sizes added to the default clouds (default 1M,5M,20M)")
    p.add_argument("--scaling-points", type=count_list,
                   default=count_list("0.1M,0.2M,0.5M,1M,2M,5M,10M,20M"),
                   help="torus sizes of the point scaling (default 0.1M,0.2M,0.5M,1M,2M,5M,10M,20M)")
    p.add_argument("--with-50m", action="store_true",
                   help="add a 50M-point torus to the point scaling (~10 GB of memory)")
    p.add_argument("--scaling-threads", type=int_list, default=default_threads,
                   help=f"thread counts of the thread scaling (default {','.join(map(str, default_threads))})")
    p.add_argument("--threads-cloud", type=count, default=count("5M"),
                   help="torus size of the thread scaling (default 5M)")
    p.add_argument("--scaling-runs", type=int, help="runs per scaling point (default: --runs)")
    p.add_argument("--no-compare", action="store_true", help="skip the comparison")
    p.add_argument("--no-scaling", action="store_true", help="skip both scalings")
    p.add_argument("--no-plots", action="store_true", help="skip the charts")
    p.add_argument("--out", default="bench/results", help="result folder (default: bench/results)")
    args = p.parse_args()
    if args.runs < 1 or args.threads < 1:
        die("--runs and --threads must be at least 1")
    args.scaling_runs = args.scaling_runs or args.runs
    if args.with_50m:
        args.scaling_points.append(50_000_000)
    return args


def in_repo(path):
    path = Path(path)
    return path if path.is_absolute() else REPO / path


# ---- the machine and the code ------------------------------------------------------------------

def machine():
    cpu = "unknown"
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break
    ram_kb = 0
    for line in Path("/proc/meminfo").read_text().splitlines():
        if line.startswith("MemTotal:"):
            ram_kb = int(line.split()[1])
    # g2s runs with glibc's huge pages for malloc (docs/pipeline.md, "Memory"): they count only
    # where the kernel's mode (the bracketed word) is not "never", or unless the run's
    # GLIBC_TUNABLES turns them off, so both go with the figures.
    thp = Path("/sys/kernel/mm/transparent_hugepage/enabled")
    text = thp.read_text() if thp.exists() else ""
    huge_pages = text.split("[", 1)[1].split("]", 1)[0] if "[" in text else "unknown"
    return {"arch": platform.machine(), "cpu": cpu, "cores": os.cpu_count(),
            "ram_mb": round(ram_kb / 1024), "kernel": platform.release(),
            "transparent_hugepage": huge_pages, "glibc_tunables": os.environ.get("GLIBC_TUNABLES", "")}


def git(*args):
    result = subprocess.run(["git", "-C", str(REPO), *args], capture_output=True, text=True)
    return result.stdout.strip() if result.returncode == 0 else ""


def load_average():
    return [round(x, 2) for x in os.getloadavg()]


# ---- one timed run ------------------------------------------------------------------------------

class Runner:
    def __init__(self, tmp):
        self.tmp = tmp

    def run(self, command, timeout=None, memory_gb=0, env=None):
        """Runs command under GNU time (and coreutils timeout); returns a dict with exit_code,
        wall (seconds, measured here), rss_kb (GNU time's maximum resident set size), the parsed
        JSON of its stdout (or None) and the start of its stderr."""
        time_file = self.tmp / "time.txt"
        full = ["/usr/bin/time", "-v", "-o", str(time_file)]
        if timeout:
            full += ["timeout", "-k", "10", str(timeout)]
        full += command

        def limit():
            if memory_gb:
                size = int(memory_gb * 2**30)
                resource.setrlimit(resource.RLIMIT_AS, (size, size))

        start = time.monotonic()
        proc = subprocess.run(full, capture_output=True, text=True, preexec_fn=limit,
                              env={**os.environ, **(env or {})})
        wall = time.monotonic() - start
        rss_kb = None
        if time_file.exists():
            for line in time_file.read_text().splitlines():
                if "Maximum resident set size (kbytes):" in line:
                    rss_kb = int(line.rsplit(":", 1)[1])
            time_file.unlink()
        output = None
        for line in reversed(proc.stdout.splitlines()):
            if line.startswith("{"):
                try:
                    output = json.loads(line)
                except json.JSONDecodeError:
                    pass
                break
        return {"exit_code": proc.returncode, "wall": wall, "rss_kb": rss_kb, "output": output,
                "stderr": proc.stderr[:400]}


def summary(values):
    return {"median": round(statistics.median(values), 3), "min": round(min(values), 3),
            "max": round(max(values), 3)}


# ---- clouds -------------------------------------------------------------------------------------

def ply_points(path):
    """The vertex count of a PLY header (None for other files or a bad header)."""
    try:
        with open(path, "rb") as f:
            if f.readline().strip() != b"ply":
                return None
            for _ in range(10_000):
                line = f.readline()
                if not line or line.strip() == b"end_header":
                    return None
                words = line.split()
                if len(words) == 3 and words[:2] == [b"element", b"vertex"]:
                    return int(words[2])
    except (OSError, ValueError):
        return None
    return None


class Synth:
    """Synthetic tori made with `g2s synth`, once each, kept in the temporary folder."""

    def __init__(self, g2s, tmp):
        self.g2s, self.tmp, self.made = g2s, tmp, {}

    def torus(self, points):
        if points not in self.made:
            path = self.tmp / f"synthetic-torus-{label(points)}.ply"
            log(f"making {path.name}: g2s synth torus --points {points}")
            result = subprocess.run([self.g2s, "synth", "torus", "--points", str(points), "-o",
                                     str(path)], capture_output=True, text=True)
            if result.returncode != 0:
                die(f"g2s synth failed (exit {result.returncode}): {result.stderr.strip()}")
            self.made[points] = path
        return self.made[points]

    def drop(self, points):
        """Removes a torus no later part needs (the 20M one is 240 MB)."""
        path = self.made.pop(points, None)
        if path:
            path.unlink(missing_ok=True)


# ---- the comparison -----------------------------------------------------------------------------

def method_command(method, binary, cloud, mesh, threads):
    if method == "g2s":
        return [binary, "mesh", str(cloud), "-o", str(mesh), "--json", "--no-stats",
                "--threads", str(threads)]
    return [binary, str(cloud), str(mesh)]


def mesh_stats(g2s, mesh, cloud):
    result = subprocess.run([g2s, "stats", str(mesh), "--points", str(cloud), "--json"],
                            capture_output=True, text=True)
    if result.returncode != 0:
        return None, f"g2s stats failed (exit {result.returncode}): {result.stderr[:400]}"
    return json.loads(result.stdout), None


def compare(args, g2s, peers, clouds, runner, tmp):
    """Runs every method on every cloud, alternating methods run by run. Returns the rows."""
    rows = []
    skip_after = {}  # peer -> points of the cloud it timed out on
    for index, (name, cloud, points) in enumerate(clouds, 1):
        methods = [("g2s", g2s)] + list(peers.items())
        results = {m: {"runs": [], "failure": None} for m, _ in methods}
        for m, _ in methods:
            if m in skip_after and points is not None and points >= skip_after[m][0]:
                results[m]["failure"] = {"kind": "skipped", "error": f"timed out on "
                                         f"{skip_after[m][1]} ({group(skip_after[m][0])} points)"}
        for r in range(1, args.runs + 1):
            for m, binary in methods:
                state = results[m]
                if state["failure"]:
                    continue
                mesh = tmp / f"{m}.stl"
                mesh.unlink(missing_ok=True)
                peer = m != "g2s"
                result = runner.run(
                    method_command(m, binary, cloud, mesh, args.threads),
                    timeout=args.peer_timeout if peer else None,
                    memory_gb=args.peer_memory_gb if peer else 0,
                    env={"OMP_NUM_THREADS": str(args.threads)} if peer else None)
                prefix = f"[{index}/{len(clouds)}] {name} {m} run {r}/{args.runs}"
                if result["exit_code"] != 0 or not result["output"]:
                    timed_out = peer and result["exit_code"] in (124, 137)  # TERM, then KILL
                    kind = "timeout" if timed_out else "failed"
                    error = (f"stopped after {args.peer_timeout:g} s" if timed_out
                             else result["stderr"].strip())
                    state["failure"] = {"kind": kind, "exit_code": result["exit_code"],
                                        "error": error}
                    log(f"{prefix}: {kind.upper()} (exit {result['exit_code']}) {error}")
                    if timed_out and points is not None:
                        skip_after[m] = (points, name)
                    continue
                out = result["output"]
                state["runs"].append({"wall": round(result["wall"], 3),
                                      "seconds": out.get("seconds"),
                                      "seconds_reconstruction": reconstruction_seconds(m, out),
                                      "rss_kb": result["rss_kb"], "points": out.get("points"),
                                      "triangles": out.get("triangles")})
                log(f"{prefix}: {out.get('points')} points -> {out.get('triangles')} triangles, "
                    f"wall {result['wall']:.2f} s, peak RSS {result['rss_kb']} kB")
                if r == args.runs:
                    state["stats"], state["stats_error"] = mesh_stats(g2s, mesh, cloud)
                mesh.unlink(missing_ok=True)
        rows += cloud_rows(name, cloud, methods, results)
    return rows


def reconstruction_seconds(method, out):
    """Seconds of the reconstruction alone: g2s's grid + growth + clean-up stages, a peer's own
    timing (normals and spacing included); reading and writing are left out of both."""
    if method == "g2s":
        parts = [out.get(k) for k in ("seconds_grid", "seconds_grow", "seconds_cleanup")]
        return round(sum(parts), 3) if None not in parts else None
    return out.get("seconds")


def cloud_rows(name, cloud, methods, results):
    rows, base = [], None
    for m, _ in methods:
        state = results[m]
        row = {"cloud": name, "path": str(cloud), "method": m}
        if not state["runs"]:
            row.update(state["failure"])
            rows.append(row)
            continue
        runs = state["runs"]
        walls = [x["wall"] for x in runs]
        recon = [x["seconds_reconstruction"] for x in runs if x["seconds_reconstruction"] is not None]
        rss = [x["rss_kb"] for x in runs if x["rss_kb"] is not None]
        row.update({
            "kind": "ok" if not state["failure"] else "partial",
            "points": runs[-1]["points"], "triangles": runs[-1]["triangles"], "runs": runs,
            "wall_seconds": summary(walls),
            "reconstruction_seconds": summary(recon) if recon else None,
            "ktriangles_per_second": round(runs[-1]["triangles"] / statistics.median(walls) / 1000, 1),
            "peak_rss_mb": round(max(rss) / 1024) if rss else None,
            "stats": state.get("stats"), "stats_error": state.get("stats_error"),
        })
        if state["failure"]:
            row["failure"] = state["failure"]
        if m == "g2s":
            base = row
        elif base and base.get("wall_seconds"):
            row["wall_ratio_to_g2s"] = round(row["wall_seconds"]["median"] / base["wall_seconds"]["median"], 2)
            if row["reconstruction_seconds"] and base.get("reconstruction_seconds") and base["reconstruction_seconds"]["median"] > 0:
                row["reconstruction_ratio_to_g2s"] = round(
                    row["reconstruction_seconds"]["median"] / base["reconstruction_seconds"]["median"], 2)
            if row["peak_rss_mb"] and base.get("peak_rss_mb"):
                row["rss_ratio_to_g2s"] = round(row["peak_rss_mb"] / base["peak_rss_mb"], 2)
        rows.append(row)
    return rows


# ---- scaling ------------------------------------------------------------------------------------

def scale_point(runner, g2s, cloud, threads, runs, tmp):
    mesh = tmp / "scaling.stl"
    walls, rss, out = [], [], None
    for _ in range(runs):
        result = runner.run(method_command("g2s", g2s, cloud, mesh, threads))
        mesh.unlink(missing_ok=True)
        if result["exit_code"] != 0 or not result["output"]:
            return {"kind": "failed", "exit_code": result["exit_code"], "error": result["stderr"].strip()}
        walls.append(round(result["wall"], 3))
        rss.append(result["rss_kb"])
        out = result["output"]
    return {"kind": "ok", "points": out["points"], "triangles": out["triangles"],
            "wall_seconds": summary(walls), "walls": walls,
            "ktriangles_per_second": round(out["triangles"] / statistics.median(walls) / 1000, 1),
            "peak_rss_mb": round(max(rss) / 1024), "rss_kb": rss}


def scaling(args, g2s, runner, synth, tmp):
    by_points, by_threads = [], []
    for points in sorted(args.scaling_points):
        cloud = synth.torus(points)
        row = {"target_points": points, "threads": args.threads,
               **scale_point(runner, g2s, cloud, args.threads, args.scaling_runs, tmp)}
        log(f"scaling points {label(points)}: {row.get('wall_seconds')} s, {row.get('peak_rss_mb')} MB")
        by_points.append(row)
        if points != args.threads_cloud:
            synth.drop(points)
    cloud = synth.torus(args.threads_cloud)
    walls = {t: [] for t in args.scaling_threads}
    rows = {}
    mesh = tmp / "threads.stl"
    for _ in range(args.scaling_runs):  # thread counts alternate run by run
        for t in args.scaling_threads:
            if rows.get(t, {}).get("kind") == "failed":
                continue
            result = runner.run(method_command("g2s", g2s, cloud, mesh, t))
            mesh.unlink(missing_ok=True)
            if result["exit_code"] != 0 or not result["output"]:
                rows[t] = {"kind": "failed", "exit_code": result["exit_code"], "error": result["stderr"].strip()}
                continue
            walls[t].append((round(result["wall"], 3), result["rss_kb"], result["output"]))
    for t in args.scaling_threads:
        if t not in rows:
            w = [x[0] for x in walls[t]]
            out = walls[t][-1][2]
            rows[t] = {"kind": "ok", "points": out["points"], "triangles": out["triangles"],
                       "wall_seconds": summary(w), "walls": w,
                       "ktriangles_per_second": round(out["triangles"] / statistics.median(w) / 1000, 1),
                       "peak_rss_mb": round(max(x[1] for x in walls[t]) / 1024)}
        base = rows[args.scaling_threads[0]]
        if rows[t]["kind"] == "ok" and base["kind"] == "ok":
            rows[t]["speedup"] = round(base["wall_seconds"]["median"] / rows[t]["wall_seconds"]["median"], 2)
        by_threads.append({"threads": t, "target_points": args.threads_cloud, **rows[t]})
        log(f"scaling threads {t}: {rows[t].get('wall_seconds')} s")
    return by_points, by_threads


# ---- Markdown -----------------------------------------------------------------------------------

def seconds_cell(s):
    digits = 3 if s["median"] < 10 else 2
    return f"{s['median']:.{digits}f} [{s['min']:.{digits}f}–{s['max']:.{digits}f}]"


def compare_table(rows):
    head = ("| cloud | method | points | triangles | wall s, median [min–max] | × g2s time | "
            "k-triangles/s | peak RSS MB | × g2s RSS | non-manifold edges | non-manifold vertices | "
            "orientation conflicts | boundary edges | holes | coverage % |")
    lines = [head, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for row in rows:
        if "wall_seconds" not in row:
            what = {"timeout": "timeout", "skipped": "skipped"}.get(row["kind"], f"failed (exit {row.get('exit_code')})")
            note = f" ({row['error']})" if row["kind"] in ("skipped", "timeout") else ""
            lines.append(f"| {row['cloud']} | {row['method']} | — | — | {what}{note} | — | — | — | — | — | — | — | — | — | — |")
            continue
        stats = row.get("stats") or {}
        defects = " | ".join(group(stats.get(k)) for k in DEFECTS)
        coverage = f"{100 * stats['coverage']:.2f}" if "coverage" in stats else "—"
        wall = seconds_cell(row["wall_seconds"])
        if row.get("failure"):
            wall += f" ({row['failure']['kind']} in a later run)"
        ratio = f"{row['wall_ratio_to_g2s']:.2f}" if "wall_ratio_to_g2s" in row else ("1" if row["method"] == "g2s" else "—")
        rss_ratio = f"{row['rss_ratio_to_g2s']:.2f}" if "rss_ratio_to_g2s" in row else ("1" if row["method"] == "g2s" else "—")
        lines.append(f"| {row['cloud']} | {row['method']} | {group(row['points'])} | {group(row['triangles'])} | "
                     f"{wall} | {ratio} | {row['ktriangles_per_second']:.1f} | {row['peak_rss_mb']} | {rss_ratio} | "
                     f"{defects} | {coverage} |")
    return lines


def scaling_table(rows, key, title):
    lines = [f"| {title} | points | triangles | wall s, median [min–max] | k-triangles/s | peak RSS MB |"
             + (" speedup |" if key == "threads" else ""),
             "|---:|---:|---:|---:|---:|---:|" + ("---:|" if key == "threads" else "")]
    for row in rows:
        first = label(row[key]) if key == "target_points" else str(row[key])
        if row["kind"] != "ok":
            lines.append(f"| {first} | — | — | failed (exit {row.get('exit_code')}) | — | — |" + (" — |" if key == "threads" else ""))
            continue
        line = (f"| {first} | {group(row['points'])} | {group(row['triangles'])} | {seconds_cell(row['wall_seconds'])} | "
                f"{row['ktriangles_per_second']:.1f} | {row['peak_rss_mb']} |")
        if key == "threads":
            line += f" {row.get('speedup', '—')} |"
        lines.append(line)
    return lines


# ---- charts -------------------------------------------------------------------------------------

def gnuplot(script, tmp):
    path = tmp / "plot.gp"
    path.write_text(script)
    result = subprocess.run(["gnuplot", str(path)], capture_output=True, text=True)
    if result.returncode != 0:
        log(f"gnuplot failed: {result.stderr.strip()}")
        return False
    return True


def plot_points(rows, png, title, tmp):
    data = tmp / "points.dat"
    ok = [r for r in rows if r["kind"] == "ok"]
    data.write_text("".join(f"{r['points']} {r['ktriangles_per_second']} {r['peak_rss_mb']} "
                            f"{r['wall_seconds']['median']}\n" for r in ok))
    return gnuplot(f"""set terminal pngcairo size 1200,450 font ",10"
set output "{png}"
set multiplot layout 1,3 title "{title}"
set logscale x
set xlabel "points"
set grid
set format x "%.0s%c"
set key off
set title "throughput (k triangles/s)"
set yrange [0:*]
plot "{data}" using 1:2 with linespoints pt 7 lw 2
set title "peak RSS (MB)"
set logscale y
set yrange [*:*]
plot "{data}" using 1:3 with linespoints pt 7 lw 2 lc 2
set title "wall seconds"
plot "{data}" using 1:4 with linespoints pt 7 lw 2 lc 3
unset multiplot
""", tmp)


def plot_threads(rows, png, title, tmp):
    data = tmp / "threads.dat"
    ok = [r for r in rows if r["kind"] == "ok"]
    data.write_text("".join(f"{r['threads']} {r['ktriangles_per_second']} {r.get('speedup', 1)}\n" for r in ok))
    top = max(r["threads"] for r in ok) if ok else 1
    return gnuplot(f"""set terminal pngcairo size 900,400 font ",10"
set output "{png}"
set multiplot layout 1,2 title "{title}"
set xlabel "threads"
set xrange [0.5:{top + 0.5}]
set xtics 1
set grid
set key off
set title "throughput (k triangles/s)"
set yrange [0:*]
plot "{data}" using 1:2 with linespoints pt 7 lw 2
set title "speedup over {ok[0]['threads'] if ok else 1} thread(s)"
set yrange [0:{top + 0.5}]
plot "{data}" using 1:3 with linespoints pt 7 lw 2 lc 2, x with lines dt 2 lc 0
unset multiplot
""", tmp)


def plot_peers(rows, peers, png, title, tmp):
    clouds = list(dict.fromkeys(r["cloud"] for r in rows))
    data = tmp / "peers.dat"
    lines = []
    for c in clouds:
        by = {r["method"]: r for r in rows if r["cloud"] == c}
        cells = []
        for m in peers:
            r = by.get(m, {})
            cells.append(str(r["wall_ratio_to_g2s"]) if "wall_ratio_to_g2s" in r else "NaN")
        lines.append(f"\"{c}\" " + " ".join(cells) + "\n")
    data.write_text("".join(lines))
    plots = ", ".join(f'"{data}" using {i + 2}:xtic(1) title "{m}"' for i, m in enumerate(peers))
    return gnuplot(f"""set terminal pngcairo size 1200,500 font ",10"
set output "{png}"
set title "{title}"
set style data histogram
set style histogram cluster gap 1
set style fill solid 0.8 border -1
set logscale y
set yrange [0.1:*]
set ylabel "wall time / g2s wall time (log; 1 = as fast as g2s)"
set xtics rotate by -30
set grid y
set arrow from graph 0, first 1 to graph 1, first 1 nohead dt 2 lc 0
set key top left
plot {plots}
""", tmp)


# ---- main ---------------------------------------------------------------------------------------

def main():
    args = parse_args()
    g2s = in_repo(args.build) / "g2s"
    if not os.access(g2s, os.X_OK):
        die(f"no g2s binary at {g2s}: build first (cmake -S . -B build -G Ninja && cmake --build build)")
    if not os.access("/usr/bin/time", os.X_OK):
        die("GNU time is needed at /usr/bin/time (apt-get install time)")
    peers_build = in_repo(args.peers_build or args.build)
    if args.peers == "none" or args.no_compare:
        peers = {}
    elif args.peers == "all":
        peers = {m: peers_build / p for m, p in PEERS.items() if os.access(peers_build / p, os.X_OK)}
        missing = sorted(set(PEERS) - set(peers))
        if missing:
            log(f"peers not built in {peers_build} (configure with -DG2S_BUILD_PEERS=ON): {', '.join(missing)}")
    else:
        peers = {}
        for m in args.peers.split(","):
            if m not in PEERS:
                die(f"unknown peer '{m}' (known: {', '.join(PEERS)})")
            if not os.access(peers_build / PEERS[m], os.X_OK):
                die(f"no {m} driver at {peers_build / PEERS[m]}: configure with -DG2S_BUILD_PEERS=ON and build")
            peers[m] = peers_build / PEERS[m]
    plots = not args.no_plots and shutil.which("gnuplot")
    if not args.no_plots and not plots:
        log("gnuplot not found (bench/peers/install.sh installs it): no charts")

    out_dir = in_repo(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    now = datetime.datetime.now(datetime.timezone.utc)
    commit = git("rev-parse", "--short", "HEAD") or "unknown"
    changes = [line[3:] for line in git("status", "--porcelain", "--", "src", "include", "tools",
                                        "bench", "CMakeLists.txt").splitlines() if line]
    stem = f"{now:%Y-%m-%d}-{commit}"
    k = 2
    while (out_dir / f"{stem}.json").exists():
        stem, k = f"{now:%Y-%m-%d}-{commit}-{k}", k + 1
    host = machine()
    version = subprocess.run([g2s, "--version"], capture_output=True, text=True).stdout.strip()
    log(f"g2s: {g2s} ({version}), commit {commit}{' plus uncommitted changes' if changes else ''}")
    log(f"machine: {host['arch']}, {host['cpu']}, {host['cores']} cores, {host['ram_mb']} MB RAM; "
        f"load {load_average()}; peers: {', '.join(peers) or 'none'}")

    with tempfile.TemporaryDirectory(prefix="g2s-bench.") as tmp_name:
        tmp = Path(tmp_name)
        runner, synth = Runner(tmp), Synth(g2s, tmp)
        result = {
            "date": now.strftime("%Y-%m-%dT%H:%M:%SZ"), "commit": commit,
            "uncommitted_changes": changes, "g2s": version,
            "g2s_built": datetime.datetime.fromtimestamp(g2s.stat().st_mtime, datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "machine": host, "load_average_start": load_average(),
            "options": {"runs": args.runs, "threads": args.threads, "peer_timeout_seconds": args.peer_timeout,
                        "peer_memory_gb": args.peer_memory_gb, "scaling_runs": args.scaling_runs},
            "peers": list(peers),
            "commands": {
                "g2s": "g2s mesh CLOUD -o OUT.stl --json --no-stats --threads N",
                "peer": "OMP_NUM_THREADS=N PEER CLOUD OUT.stl (bench/peers/)",
                "measure": "/usr/bin/time -v [timeout] COMMAND; g2s stats OUT.stl --points CLOUD --json",
            },
        }
        md = [f"g2s {commit}{' plus uncommitted changes (' + ', '.join(changes) + ')' if changes else ''}, "
              f"{result['date']}; {host['arch']}, {host['cpu']}, {host['cores']} cores, {host['ram_mb']:,} MB RAM; "
              f"load average at start {result['load_average_start'][0]}", ""]

        if not args.no_compare:
            if args.clouds:
                clouds = [(Path(c).stem, Path(c).resolve(), ply_points(c)) for c in args.clouds]
            else:
                data = in_repo(os.environ.get("G2S_DATA_DIR", "../shared/data"))
                clouds = [(p.stem, p, ply_points(p)) for p in sorted(data.glob("*.ply"))]
                if not clouds:
                    log(f"no *.ply in {data} (set G2S_DATA_DIR): synthetic clouds only")
                clouds += [(f"synthetic-torus-{label(n)}", synth.torus(n), n) for n in args.synthetic]
            clouds.sort(key=lambda c: (c[2] is None, c[2] or 0))  # small first: timeouts skip larger
            result["compare"] = compare(args, g2s, peers, clouds, runner, tmp)
            md += [f"### g2s and peers, `--threads {args.threads}`, {args.runs} runs each, alternating",
                   "", *compare_table(result["compare"]), ""]
            if plots and peers:
                png = out_dir / f"{stem}-peers.png"
                if plot_peers(result["compare"], list(peers), png,
                              f"Peers' wall time relative to g2s ({host['cpu']}, {args.threads} thread(s), commit {commit})", tmp):
                    md += [f"![peer comparison]({png.name})", ""]
            for n in args.synthetic:
                if n not in args.scaling_points and n != args.threads_cloud:
                    synth.drop(n)

        if not args.no_scaling:
            by_points, by_threads = scaling(args, g2s, runner, synth, tmp)
            result["scaling_points"], result["scaling_threads"] = by_points, by_threads
            md += [f"### g2s against point count (synthetic torus, `--threads {args.threads}`, {args.scaling_runs} runs each)",
                   "", *scaling_table(by_points, "target_points", "torus"), ""]
            if plots:
                png = out_dir / f"{stem}-points.png"
                if plot_points(by_points, png, f"g2s against point count, {args.threads} thread(s) ({host['cpu']}, commit {commit})", tmp):
                    md += [f"![scaling with points]({png.name})", ""]
            md += [f"### g2s against threads ({label(args.threads_cloud)}-point torus, {args.scaling_runs} runs each, alternating)",
                   "", *scaling_table(by_threads, "threads", "threads"), ""]
            if plots:
                png = out_dir / f"{stem}-threads.png"
                if plot_threads(by_threads, png, f"g2s on a {label(args.threads_cloud)}-point torus against threads ({host['cpu']}, {host['cores']} cores)", tmp):
                    md += [f"![scaling with threads]({png.name})", ""]

        result["load_average_end"] = load_average()
        (out_dir / f"{stem}.json").write_text(json.dumps(result, indent=1) + "\n")
        (out_dir / f"{stem}.md").write_text("\n".join(md))
    print("\n".join(md))
    log(f"wrote {out_dir / stem}.json, .md" + (" and charts" if plots else ""))


if __name__ == "__main__":
    main()
