"""A swinging rope from a few lines of numpy physics, drawn by the wire runtime (docs/python.md).

    PYTHONPATH=build/python /usr/bin/python3 python/examples/swinging_rope.py [OUT_DIR] [FRAMES]

Verlet integration with distance constraints: 32 nodes, fixed at the first one, released horizontal. Every frame the
nodes go to the runtime, which runs the C++ wire systems; every 30th frame is written as OUT_DIR/rope_NNNN.png
(default out/python_rope, 120 frames). Prints the wall time per frame of the physics, set_nodes + update and the
render (of the frames rendered), and the C++ systems' own time within the update.
"""
import sys
import time
from pathlib import Path

import numpy as np

import wires

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/python_rope")
frames = int(sys.argv[2]) if len(sys.argv) > 2 else 120
out.mkdir(parents=True, exist_ok=True)

n, length, dt = 32, 2.0, 1.0 / 60.0
rest = length / (n - 1)
x = np.stack([np.linspace(0.0, length, n), np.full(n, 1.0), np.zeros(n)], axis=1)  # horizontal, fixed at node 0
previous = x.copy()
gravity = np.array([0.0, -9.81, 0.0])

rt = wires.Runtime(640, 360)  # headless; wires.Runtime(headless=False) opens a window
rope = rt.spawn(x, radius=0.03, material=rt.add_material((0.9, 0.5, 0.2)))
rt.set_camera(eye=(0.0, 0.2, 3.4), target=(0.0, -0.2, 0.0))
rt.lod_tolerance_px = 0.5

timing = {"physics": 0.0, "update": 0.0, "render": 0.0}
renders = 0
systems_ms = 0.0  # the C++ systems' own time inside update(), as the ECS schedule measures it
for frame in range(frames):
    t0 = time.perf_counter()
    x, previous = x + (x - previous) * 0.999 + gravity * dt * dt, x  # Verlet step with a little damping
    for _ in range(20):  # keep each element at its rest length; node 0 stays on its hook
        d = x[1:] - x[:-1]
        dist = np.linalg.norm(d, axis=1, keepdims=True)
        fix = 0.5 * (dist - rest) / dist * d
        x[:-1] += fix
        x[1:] -= fix
        x[0] = (0.0, 1.0, 0.0)
    t1 = time.perf_counter()
    rt.set_nodes(rope, x)
    rt.update(dt)  # the C++ wire systems: curve, LOD, rings, mesh, draw list
    t2 = time.perf_counter()
    timing["physics"] += t1 - t0
    timing["update"] += t2 - t1
    systems_ms += rt.stats["systems_total_ms"]
    if frame % 30 == 0 or frame == frames - 1:
        image = rt.render()  # (360, 640, 4) uint8 RGBA
        timing["render"] += time.perf_counter() - t2
        renders += 1
        wires.Runtime.save_png(str(out / f"rope_{frame:04d}.png"), image)

rings = rt.rings(rope)  # numpy arrays: centres, tangents, normals, binormals, radius, u, segment, t
print(f"{frames} frames on {rt.gl_renderer}: {len(rings['centres'])} rings, tip at {np.round(x[-1], 3)}")
print(f"ms per frame: physics {1000.0 * timing['physics'] / frames:.3f}, set_nodes + update "
      f"{1000.0 * timing['update'] / frames:.3f} (the C++ systems {systems_ms / frames:.3f} of it), "
      f"render + read-back {1000.0 * timing['render'] / renders:.3f} (per rendered frame)")
print(f"wrote {out}/rope_*.png")
