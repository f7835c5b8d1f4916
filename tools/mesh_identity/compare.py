#!/usr/bin/env python3
"""Compare `wiretool mesh` outputs of two builds, byte for byte, on a fixed-seed family of wire files.

Usage: tools/mesh_identity/compare.py BASE_WIRETOOL NEW_WIRETOOL [--cases N] [--seed S] [--keep DIR]

The family (regenerated from the seed, so the inputs are kept as this script): open and closed wires of 2-200
nodes, uniform / end-dense / jittered spacing, catenary sag, zig-zags, helices, coincident and near-coincident
nodes, 1e5 m from the origin, every spline type, per-node radius and stretch, KB/TCB and physics tension, and
multi-frame scenes with nodes inserted and removed (the pop-free blend) and moving cameras; each case is run with
fixed rings per segment and with an adaptive tolerance. Exit 0 when every glb and csv is identical (and both
builds agree on the exit status), 1 otherwise, listing the cases that differ.
"""
import argparse
import json
import math
import os
import random
import subprocess
import sys
import tempfile


def spacing(rng, n, kind):
    if kind == "uniform":
        w = [1.0] * (n - 1)
    elif kind == "end-dense":
        w = [0.05 + abs(math.cos(math.pi * (i + 0.5) / (n - 1))) ** 3 for i in range(n - 1)]
    else:
        w = [rng.uniform(0.3, 1.7) for _ in range(n - 1)]
    s = [0.0]
    for x in w:
        s.append(s[-1] + x)
    return [v / s[-1] for v in s]


def shape(rng, n, kind, length, origin):
    t = spacing(rng, n, rng.choice(["uniform", "end-dense", "jitter"]))
    pts = []
    sag = rng.uniform(0.02, 0.4) * length
    for i, u in enumerate(t):
        if kind == "catenary":
            p = [u * length, -sag * 4 * u * (1 - u), 0.0]
        elif kind == "zigzag":
            p = [u * length, (0.1 * length if i % 2 else 0.0), 0.0]
        elif kind == "helix":
            a = u * rng.uniform(2, 12)
            p = [0.2 * length * math.cos(a), 0.2 * length * math.sin(a), u * length]
        elif kind == "loop":
            a = 2 * math.pi * i / n
            p = [0.3 * length * math.cos(a), 0.3 * length * math.sin(a), 0.05 * length * math.sin(3 * a)]
        else:  # random walk
            p = [u * length + rng.uniform(-0.1, 0.1) * length, rng.uniform(-0.2, 0.2) * length,
                 rng.uniform(-0.2, 0.2) * length]
        pts.append([p[0] + origin[0], p[1] + origin[1], p[2] + origin[2]])
    if kind != "loop" and n > 4 and rng.random() < 0.2:  # coincident / near-coincident pair
        k = rng.randrange(1, n - 1)
        eps = rng.choice([0.0, 1e-9, 1e-6])
        pts[k] = [pts[k - 1][0] + eps, pts[k - 1][1], pts[k - 1][2]]
    return pts


def wire(rng, case):
    kind = rng.choice(["catenary", "zigzag", "helix", "loop", "walk"])
    n = rng.choice([2, 3, 4, 5, 8, 13, 24, 40, 64, 120, 200])
    if kind == "loop":
        n = max(n, 3)
    length = 10 ** rng.uniform(-1.5, 2.5)
    origin = [0.0, 0.0, 0.0] if rng.random() < 0.7 else [1e5, -3e4, 2e5]
    pts = shape(rng, n, kind, length, origin)
    w = {"radius": round(length * 10 ** rng.uniform(-3.5, -1.2), 9)}
    if kind == "loop" and n >= 3:
        w["closed"] = True
    sp = rng.choice(["uniform", "centripetal", "chordal", "c2", "auto", "auto"])
    w["spline"] = {"type": sp}
    if sp in ("uniform", "centripetal", "chordal") and rng.random() < 0.3:
        w["spline"]["tension"] = round(rng.uniform(-0.5, 0.8), 3)
    nodes = []
    for i, p in enumerate(pts):
        if rng.random() < 0.5:
            node = {"p": p, "id": 100 + 10 * i}
            if rng.random() < 0.3:
                node["stretch"] = round(rng.uniform(0.8, 1.5), 4)
            if rng.random() < 0.15:
                node["radius"] = round(w["radius"] * rng.uniform(0.5, 2.0), 9)
            nodes.append(node)
        else:
            nodes.append({"p": p, "id": 100 + 10 * i})
    w["nodes"] = nodes
    if rng.random() < 0.3:
        w["sides"] = rng.choice([3, 5, 8, 16, 24])
    if rng.random() < 0.2:
        w["caps"] = False
    return w


def frames(rng, base):
    """A scene over several frames: the nodes move, nodes are inserted (on the curve) and removed."""
    out = []
    cur = json.loads(json.dumps(base))
    next_id = 10_000
    for f in range(rng.randint(3, 8)):
        cur = json.loads(json.dumps(cur))
        for w in cur["wires"]:
            ns = w["nodes"]
            for node in ns:
                node["p"] = [c + rng.uniform(-0.01, 0.01) for c in node["p"]]
            r = rng.random()
            if r < 0.35 and len(ns) >= 2:
                k = rng.randrange(0, len(ns) - 1)
                mid = [(a + b) / 2 for a, b in zip(ns[k]["p"], ns[k + 1]["p"])]
                ns.insert(k + 1, {"p": mid, "id": next_id})
                next_id += 1
            elif r < 0.6 and len(ns) > (4 if w.get("closed") else 3):
                del ns[rng.randrange(0, len(ns))]
        frame = {"wires": cur["wires"]}
        if rng.random() < 0.5:
            frame["camera"] = {"eye": [rng.uniform(-20, 20), rng.uniform(1, 20), rng.uniform(5, 40)],
                               "target": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 45}
        out.append(frame)
    return {"frames": out}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("base")
    ap.add_argument("new")
    ap.add_argument("--cases", type=int, default=60)
    ap.add_argument("--seed", type=int, default=20261128)
    ap.add_argument("--keep", help="write inputs and outputs here instead of a temporary folder")
    a = ap.parse_args()
    rng = random.Random(a.seed)
    root = a.keep or tempfile.mkdtemp(prefix="mesh_identity_")
    os.makedirs(root, exist_ok=True)
    differ = []
    runs = 0
    for c in range(a.cases):
        wires = {"wires": [wire(rng, c) for _ in range(rng.randint(1, 3))]}
        scene = frames(rng, wires) if rng.random() < 0.4 else wires
        path = os.path.join(root, f"case_{c:03d}.json")
        with open(path, "w") as fh:
            json.dump(scene, fh)
        for opt in (["--rings-per-segment", str(rng.choice([1, 3, 8]))], ["--tolerance", f"{10 ** rng.uniform(-4, -1):.6g}"]):
            runs += 1
            outs = []
            for tag, exe in (("base", a.base), ("new", a.new)):
                glb = os.path.join(root, f"case_{c:03d}{opt[0]}.{tag}.glb")
                csv = os.path.join(root, f"case_{c:03d}{opt[0]}.{tag}.csv")
                r = subprocess.run([exe, "mesh", path, "-o", glb, "--csv", csv] + opt, capture_output=True)
                data = b""
                for f in (glb, csv):
                    if os.path.exists(f):
                        with open(f, "rb") as fh:
                            data += fh.read()
                outs.append((r.returncode, r.stderr, data))
            if outs[0] != outs[1]:
                differ.append(f"case_{c:03d} {' '.join(opt)}: exit {outs[0][0]} vs {outs[1][0]}, "
                              f"{len(outs[0][2])} vs {len(outs[1][2])} bytes")
    for d in differ:
        print("DIFFERS:", d)
    print(f"mesh_identity: {runs - len(differ)} of {runs} runs identical ({a.cases} cases, seed {a.seed}, in {root})")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
