#!/usr/bin/env python3
"""Writes a LAS file from a float x, y, z binary PLY (what `g2s synth` writes), for benchmarks of
the LAS reader: `bench/las_from_ply.py IN.ply OUT.las [--format N] [--extra-bytes K]`.

LAS 1.4 (the 64-bit point count; the legacy count 0 for formats 6 and up), scale 1e-6 of the
cloud's extent with the offset at its lower corner, streamed in 1M-point chunks (numpy), so 20M+
points need little memory. Non-coordinate fields are zero.
"""
import argparse
import struct

import numpy as np

RECORD_SIZE = [20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67]
CHUNK = 1 << 20


def read_ply_header(f):
    count, props, line = None, [], b""
    while line.strip() != b"end_header":
        line = f.readline()
        if not line:
            raise SystemExit("not a PLY file")
        words = line.split()
        if words[:2] == [b"format", b"ascii"] or words[:2] == [b"format", b"binary_big_endian"]:
            raise SystemExit("only binary little-endian PLY")
        if words[:2] == [b"element", b"vertex"]:
            count = int(words[2])
        elif words[:1] == [b"property"] and count is not None:
            props.append((words[1], words[2]))
    if props != [(b"float", b"x"), (b"float", b"y"), (b"float", b"z")]:
        raise SystemExit("expected float x, y, z only")
    return count


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("input")
    parser.add_argument("output")
    parser.add_argument("--format", type=int, default=6, choices=range(11))
    parser.add_argument("--extra-bytes", type=int, default=0)
    args = parser.parse_args()
    with open(args.input, "rb") as f:
        count = read_ply_header(f)
        body = f.tell()
        lo = np.full(3, np.inf)
        hi = np.full(3, -np.inf)
        for first in range(0, count, CHUNK):
            xyz = np.fromfile(f, dtype="<f4", count=3 * min(CHUNK, count - first)).reshape(-1, 3)
            lo = np.minimum(lo, xyz.min(axis=0))
            hi = np.maximum(hi, xyz.max(axis=0))
        scale = np.maximum(hi - lo, 1e-9) * 1e-6
        record = RECORD_SIZE[args.format] + args.extra_bytes
        header = bytearray(375)
        header[0:4] = b"LASF"
        header[24:26] = bytes([1, 4])
        header[26:26 + 22] = b"bench/las_from_ply.py\0"
        legacy = 0 if args.format >= 6 else count
        struct.pack_into("<HIIBHI", header, 94, 375, 375, 0, args.format, record, legacy)
        struct.pack_into("<3d3d", header, 131, *scale, *lo)
        struct.pack_into("<6d", header, 179, hi[0], lo[0], hi[1], lo[1], hi[2], lo[2])
        struct.pack_into("<Q", header, 247, count)
        with open(args.output, "wb") as out:
            out.write(header)
            f.seek(body)
            for first in range(0, count, CHUNK):
                n = min(CHUNK, count - first)
                xyz = np.fromfile(f, dtype="<f4", count=3 * n).reshape(-1, 3).astype(np.float64)
                records = np.zeros((n, record), dtype=np.uint8)
                ints = np.rint((xyz - lo) / scale).astype("<i4")
                records[:, :12] = ints.view(np.uint8).reshape(n, 12)
                out.write(records.tobytes())


if __name__ == "__main__":
    main()
