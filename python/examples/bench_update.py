"""What the Python bindings add to a frame: 1,000 wires of 64 nodes moved from numpy every frame (docs/python.md).

    PYTHONPATH=build/python /usr/bin/python3 python/examples/bench_update.py [--frames 120] [--threads 1]

The scene of `wiretool bench`'s `swaying` (1,000 hanging wires 10 m across in 20 rows, every interior node moving
every frame, the same flying camera, 1920x1080, 0.5 px): the nodes are computed in numpy, handed to the runtime in one
call (Runtime.set_positions) and the C++ wire systems run (Runtime.update). Per frame it reports the wall time of the
numpy physics, of the binding calls (camera + positions + update) and the systems' own time as the C++ schedule
measures it (Runtime.stats["systems_total_ms"]); what the bindings add is calls - systems per frame (the node copy
included: a C++ game writes its nodes too), its median against the systems' median. A second pass hands the nodes over wire by wire (Runtime.set_nodes, 1,000
Python calls a frame) for comparison. Medians over the frames after the first (which builds everything). Also the
thread CPU time of handing the camera and nodes over against that of update(), which a loaded machine disturbs less
than wall time (with --threads 1 the systems run on the calling thread).
"""
import argparse
import statistics
import time

import numpy as np

import wires

parser = argparse.ArgumentParser()
parser.add_argument("--frames", type=int, default=120)
parser.add_argument("--threads", type=int, default=1)
parser.add_argument("--wires", type=int, default=1000)
args = parser.parse_args()
nodes_per_wire = 64


def hanging_field(count):
    """(count, 64, 3): wire i 10 m across in row i % 20, column i / 20, sagging 5-12% of its span (a parabola)."""
    i = np.arange(count)[:, None]
    s = np.linspace(0.0, 1.0, nodes_per_wire)[None, :]
    p1 = np.stack([np.full(count, -5.0), 0.6 * (i[:, 0] % 20), -1.5 * (i[:, 0] // 20)], axis=1)[:, None, :]
    rise = np.stack([np.full(count, 10.0), 0.3 * np.sin(0.7 * i[:, 0]), 0.2 * np.sin(0.3 * i[:, 0])], axis=1)
    sag = (0.5 + 0.05 * (i % 13)) * 4.0 * s * (1.0 - s)
    pos = p1 + rise[:, None, :] * s[..., None]
    pos[..., 1] -= sag
    return pos


def camera(frame):
    """`wiretool bench`'s standard/swaying camera (tools/wiretool/bench_systems.cpp place_camera)."""
    t = float(frame)
    eye = np.array([3.0 * np.sin(0.02 * t), 5.0 + np.sin(0.03 * t), 8.0 - 0.15 * t], dtype=np.float32)
    target = eye + np.array([0.4 * np.sin(0.01 * t), -0.15, -1.0], dtype=np.float32)
    return tuple(map(float, eye)), tuple(map(float, target))


def run(per_wire_calls):
    rt = wires.Runtime(1920, 1080, threads=args.threads)
    rt.lod_tolerance_px = 0.5
    pos = hanging_field(args.wires)
    handles = [rt.spawn(p, radius=0.01) for p in pos]
    k = np.arange(1, nodes_per_wire - 1)[None, :]
    wire_index = np.arange(args.wires)[:, None]
    physics_ms, calls_ms, systems_ms = [], [], []
    handover_cpu_ms, update_cpu_ms = [], []  # thread CPU time (with --threads 1 the systems run on this thread)
    for f in range(args.frames):
        t0 = time.perf_counter()
        if f > 0:  # the physics moved every interior node a little (ends stay on their posts)
            pos[:, 1:-1, 2] += 0.002 * np.sin(0.1 * f + 0.1 * (k + wire_index))
        t1, c1 = time.perf_counter(), time.thread_time()
        eye, target = camera(f)
        rt.set_camera(eye, target, near=0.1, far=500.0)
        if per_wire_calls:
            for w, p in zip(handles, pos):
                rt.set_nodes(w, p)
        else:
            rt.set_positions(handles, pos)
        c2 = time.thread_time()
        rt.update(1.0 / 60.0)
        t2, c3 = time.perf_counter(), time.thread_time()
        if f == 0:
            continue
        physics_ms.append(1000.0 * (t1 - t0))
        calls_ms.append(1000.0 * (t2 - t1))
        systems_ms.append(rt.stats["systems_total_ms"])
        handover_cpu_ms.append(1000.0 * (c2 - c1))
        update_cpu_ms.append(1000.0 * (c3 - c2))
    visible = rt.stats["visible_wires"]
    # The bindings' part of each frame, paired with that frame's systems time (the machine's load hits both alike).
    added_ms = [c - s for c, s in zip(calls_ms, systems_ms)]
    return (statistics.median(physics_ms), statistics.median(calls_ms), statistics.median(systems_ms),
            statistics.median(added_ms), statistics.median(handover_cpu_ms), statistics.median(update_cpu_ms), visible)


print(f"{args.wires} wires x {nodes_per_wire} nodes, every node moving, {args.frames} frames, {args.threads} thread(s)")
for label, per_wire in (("set_positions (one call)", False), ("set_nodes per wire", True)):
    physics, calls, systems, added, handover_cpu, update_cpu, visible = run(per_wire)
    print(f"{label}: {visible} visible\n"
          f"  wall: numpy physics {physics:6.3f} ms | binding calls {calls:6.3f} ms | C++ systems {systems:6.3f} ms | "
          f"bindings add {added:6.3f} ms = {100.0 * added / systems:4.1f}% of the systems\n"
          f"  CPU:  camera + nodes handed over {handover_cpu:6.3f} ms | update (the systems) {update_cpu:6.3f} ms = "
          f"{100.0 * handover_cpu / update_cpu:4.1f}%")
