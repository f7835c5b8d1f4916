"""What the Python bindings add to the bulk node stream: W wires of 64 nodes handed over in one call a frame
(Runtime.stream_nodes) against the same write in C++ (`wiretool bench --gl --scenes stream`, write_ms).

    PYTHONPATH=build/python GALLIUM_NOOP=1 /usr/bin/python3 python/examples/bench_stream.py [--wires 1000] [--frames 60]

Per frame: the wall time of stream_nodes (begin + write_many behind one Python call; numpy arrays are read in
place) and of render() (draw() plus the read-back of the image, which C++ rows do not have). Medians over the frames
after the first. The C++ figure for the same wires and thread count is write_ms in bench_gl_stream.csv.
"""
import argparse
import statistics
import time

import numpy as np

import wires

parser = argparse.ArgumentParser()
parser.add_argument("--wires", type=int, default=1000)
parser.add_argument("--frames", type=int, default=60)
parser.add_argument("--threads", type=int, default=1)
args = parser.parse_args()
nodes = 64

rt = wires.Runtime(320, 180, path="nodes", threads=args.threads)
side = int(np.ceil(np.sqrt(args.wires)))
handles = [rt.stream_add(radius=0.02, max_sides=8) for _ in range(args.wires)]
rt.set_camera((side, 2.0 * side, 2.0 * side), (side, 0.0, side), far=10.0 * side + 100.0)
k = np.arange(args.wires)
u = np.linspace(0.0, 1.0, nodes)[None, :]
stream_ms, render_ms = [], []
for f in range(args.frames):
    swing = 0.5 * np.sin(0.05 * f + 0.37 * k)[:, None]
    sag = 1.2 * u * (1.0 - u)
    pos = np.empty((args.wires, nodes, 3))
    pos[..., 0] = 2.0 * (k % side)[:, None] + 1.6 * u
    pos[..., 1] = 3.0 - sag * np.cos(swing)
    pos[..., 2] = 2.0 * (k // side)[:, None] + sag * np.sin(swing)
    t0 = time.perf_counter()
    rt.stream_nodes(handles, pos)
    t1 = time.perf_counter()
    rt.render()
    t2 = time.perf_counter()
    if f > 0:
        stream_ms.append(1e3 * (t1 - t0))
        render_ms.append(1e3 * (t2 - t1))
print(f"{args.wires} wires x {nodes} nodes, {args.threads} thread(s): stream_nodes median "
      f"{statistics.median(stream_ms):.3f} ms ({1e3 * statistics.median(stream_ms) / args.wires:.3f} us a wire), "
      f"render median {statistics.median(render_ms):.3f} ms")
