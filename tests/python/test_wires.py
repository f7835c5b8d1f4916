"""The Python module `wires` (python/wires_module.cpp) against the runtime it binds: errors, rings, pixels, memory.

Run by ctest (python_wires) as PYTHONPATH=build/python /usr/bin/python3 -m pytest -q tests/python, with WIRETOOL
pointing at build/bin/wiretool, and by tools/pip_install_test.sh against the module pip installed into a fresh
virtual environment (WIRES_EXPECTED_PREFIX: the environment the tested module must come from). Every test builds its
own runtime.
"""
import csv
import ctypes
import json
import math
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import wires

WIRETOOL = os.environ.get("WIRETOOL", str(Path(__file__).resolve().parents[2] / "build" / "bin" / "wiretool"))
CLEAR = (0.10, 0.10, 0.12, 1.0)
# The comparisons with wiretool need the program; ctest and tools/test.sh always name it (WIRETOOL), and then a
# missing one fails instead of skipping.
needs_wiretool = pytest.mark.skipif("WIRETOOL" not in os.environ and not Path(WIRETOOL).exists(),
                                    reason=f"no wiretool at {WIRETOOL} (set WIRETOOL)")


def hanging(n=16, sag=0.2, z=0.0):
    """A cable across the default view: x in [-1.5, 1.5], sagging by `sag` in the middle."""
    s = np.linspace(0.0, 1.0, n)
    return np.stack([-1.5 + 3.0 * s, 0.3 - 4.0 * sag * s * (1.0 - s), np.full(n, z)], axis=1)


def background(pixels):
    """True where a pixel is the clear colour (within 12/255)."""
    clear = np.array(CLEAR[:3]) * 255.0
    return np.all(np.abs(pixels[..., :3].astype(float) - clear) <= 12.0, axis=-1)


class _Mallinfo2(ctypes.Structure):
    _fields_ = [(name, ctypes.c_size_t) for name in
                ("arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks", "uordblks", "fordblks",
                 "keepcost")]


def heap_in_use_kib():
    """Bytes the C heap has handed out and not taken back (glibc's mallinfo2: chunks in use plus mmapped ones), in
    KiB: what a leak grows. Unlike RSS it does not move when the allocator opens an arena for a thread that
    allocates for the first time, or when pages are touched, which under CPU load happens late and unevenly."""
    libc = ctypes.CDLL("libc.so.6")
    libc.mallinfo2.restype = _Mallinfo2
    info = libc.mallinfo2()
    return (info.uordblks + info.hblkhd) // 1024


# ---- errors: Python exceptions with the runtime's messages; the runtime stays usable ----

def test_bad_nodes_raise_the_runtime_message_and_the_scene_goes_on():
    rt = wires.Runtime(320, 180)
    good = rt.spawn(hanging(), radius=0.03)
    bad_nodes = hanging(z=0.5)
    bad_nodes[3, 1] = np.nan
    bad = rt.spawn(bad_nodes, radius=0.03)
    with pytest.raises(wires.WireError) as raised:
        rt.update()
    assert isinstance(raised.value, ValueError)
    assert str(raised.value) == f"wire entity {bad.id} (index {bad.id}, version 0): node 3: position.y is NaN"
    assert rt.error(bad) == str(raised.value)
    assert rt.error(good) is None
    rt.render()  # the default (nodes) path computes the rings as it draws
    assert rt.rings(good) is not None  # the rest of the frame went on
    assert rt.stats["visible_wires"] == 1

    # Reported once: the next frame does not raise again for the same error.
    rt.update()
    # A node id used twice names both nodes.
    ids = np.arange(16)
    ids[9] = 4
    rt.set_nodes(bad, hanging(z=0.5), ids=ids)
    with pytest.raises(wires.WireError, match=r"node 9: id 4 is used twice \(also node 4\)"):
        rt.update()
    # Fixed: drawn again, no error.
    rt.set_nodes(bad, hanging(z=0.5))
    rt.update()
    assert rt.error(bad) is None
    assert rt.stats["visible_wires"] == 2
    assert rt.render().shape == (180, 320, 4)


def test_bad_arguments_raise_value_error_and_change_nothing():
    rt = wires.Runtime(160, 90)
    w = rt.spawn(hanging(), radius=0.03)
    rt.update()
    rt.render()
    before = rt.rings(w)
    with pytest.raises(ValueError, match=r"positions: expected an array of shape \(N, 3\)"):
        rt.set_nodes(w, hanging()[:, :2])
    with pytest.raises(ValueError, match=r"ids: expected one value per node \(shape \(16,\)\)"):
        rt.set_nodes(w, hanging(), ids=np.arange(15))
    with pytest.raises(ValueError, match=r"stretch: expected one value per node"):
        rt.spawn(hanging(), stretch=np.ones(3))
    with pytest.raises(ValueError, match=r"ids: node 2: id -1 is outside"):
        rt.set_nodes(w, hanging(), ids=np.array([0, 1, -1] + list(range(3, 16))))
    with pytest.raises(ValueError, match=r"unknown spline type 'bezier'"):
        rt.spawn(hanging(), spline="bezier")
    with pytest.raises(ValueError, match=r"material 7 does not exist"):
        rt.spawn(hanging(), material=7)
    with pytest.raises(ValueError, match=r"radius: must be a positive"):
        rt.spawn(hanging(), radius=-1.0)
    with pytest.raises(ValueError, match=r"camera: eye and target must differ"):
        rt.set_camera((0, 0, 1), (0, 0, 1))
    with pytest.raises(ValueError, match=r"positions: expected an array of shape \(1, N, 3\)"):
        rt.set_positions([w], hanging())
    rt.destroy(w)
    with pytest.raises(ValueError, match=rf"wire entity {w.id} .* is not a live wire"):
        rt.set_nodes(w, hanging())
    # Still usable.
    w2 = rt.spawn(hanging(), radius=0.03)
    rt.update()
    rt.render()
    after = rt.rings(w2)
    np.testing.assert_array_equal(before["centres"], after["centres"])


# ---- rings: the same as `wiretool mesh --csv` and `wiretool view --csv` for the same file ----

def read_ring_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}


def wire_file(tmp_path):
    rng = np.random.default_rng(7)
    nodes = hanging(12, 0.25) + rng.normal(0.0, 0.05, (12, 3))
    stretch = 1.0 + 0.2 * rng.random(12)
    doc = {"radius": 0.04, "spline": {"type": "auto"}, "nodes": [{"p": list(p), "id": 10 + i, "stretch": float(s)}
                                     for i, (p, s) in enumerate(zip(nodes, stretch))]}
    path = tmp_path / "cable.json"
    path.write_text(json.dumps(doc))
    return path, nodes, np.arange(10, 22), stretch.astype(np.float32)


def view_clip_planes(nodes, eye, radius_m=0.04):
    """wiretool view's clip planes (view_command.cpp): around the nodes' bounding sphere."""
    lo, hi = nodes.min(axis=0), nodes.max(axis=0)
    centre, radius = 0.5 * (lo + hi), 0.5 * math.sqrt(float(np.dot(hi - lo, hi - lo))) + radius_m
    reach = 1.25 * radius
    d = np.array(eye) - centre
    distance = math.sqrt(float(np.dot(d, d)))
    far = 1.01 * (distance + reach)
    return max(0.5 * (distance - reach), max(1e-5 * far, min(0.05, 0.01 * reach))), far


def assert_rings_equal(rings, table):
    np.testing.assert_array_equal(rings["segment"], table["segment"])
    np.testing.assert_array_equal(rings["t"], table["t"])  # %.17g: exact
    np.testing.assert_array_equal(rings["centres"], np.stack([table["x"], table["y"], table["z"]], axis=1))
    np.testing.assert_array_equal(rings["u"], table["u"])
    np.testing.assert_array_equal(rings["radius"].astype(np.float32), table["radius"].astype(np.float32))
    for key, cols in (("tangents", "t"), ("normals", "n"), ("binormals", "b")):
        csv_frame = np.stack([table[cols + "x"], table[cols + "y"], table[cols + "z"]], axis=1)
        np.testing.assert_allclose(rings[key], csv_frame, rtol=0, atol=5e-9)  # %.9g columns


@needs_wiretool
def test_mesh_rings_equal_wiretool_mesh_csv(tmp_path):
    path, nodes, ids, stretch = wire_file(tmp_path)
    out = tmp_path / "rings.csv"
    subprocess.run([WIRETOOL, "mesh", str(path), "--csv", str(out)], check=True)
    rings = wires.mesh_rings(nodes, ids=ids, stretch=stretch, radius=0.04)
    assert_rings_equal(rings, read_ring_csv(out))


@needs_wiretool
def test_runtime_rings_equal_wiretool_view_csv(tmp_path):
    path, nodes, ids, stretch = wire_file(tmp_path)
    out = tmp_path / "view.csv"
    eye, target = (0.4, 0.6, 4.0), (0.0, 0.0, 0.0)
    subprocess.run([WIRETOOL, "view", str(path), "--size", "640x360", "--camera", ",".join(map(str, eye + target)),
                    "--csv", str(out)], check=True)
    near, far = view_clip_planes(nodes, eye)

    rt = wires.Runtime(640, 360)  # both on their default path: nodes under llvmpipe
    assert rt.path == "nodes"
    w = rt.spawn(nodes, ids=ids, stretch=stretch, radius=0.04)
    rt.set_camera(eye, target, near=near, far=far)
    rt.update()
    rt.render()
    assert_rings_equal(rt.rings(w), read_ring_csv(out))


def test_nodes_path_rings_are_the_gpus_and_equal_wiretool_view_csv(tmp_path):
    """On the nodes path the rings are read back from the GPU: after render(), as `wiretool view --path nodes`
    writes them, and close to the CPU path's (float offsets, a 20-bit frame)."""
    path, nodes, ids, stretch = wire_file(tmp_path)
    out = tmp_path / "view_nodes.csv"
    eye, target = (0.4, 0.6, 4.0), (0.0, 0.0, 0.0)
    subprocess.run([WIRETOOL, "view", str(path), "--size", "640x360", "--path", "nodes", "--camera",
                    ",".join(map(str, eye + target)), "--csv", str(out)], check=True)
    table = read_ring_csv(out)
    near, far = view_clip_planes(nodes, eye)
    rings = {}
    for name in ("nodes", "cpu"):
        rt = wires.Runtime(640, 360, path=name)
        w = rt.spawn(nodes, ids=ids, stretch=stretch, radius=0.04)
        rt.set_camera(eye, target, near=near, far=far)
        rt.update()
        if name == "nodes":
            with pytest.raises(RuntimeError, match="render"):
                rt.rings(w)
        rt.render(clear=CLEAR)
        rings[name] = rt.rings(w)
    assert_rings_equal(rings["nodes"], table)
    # The CPU path's LOD may leave segments without a ring (below node resolution); every ring it places is one the
    # GPU places too, at the same point of the same curve.
    gpu, cpu = rings["nodes"], rings["cpu"]
    at = {(int(seg), float(t)): i for i, (seg, t) in enumerate(zip(gpu["segment"], gpu["t"]))}
    matched = [(at[(int(seg), float(t))], k) for k, (seg, t) in enumerate(zip(cpu["segment"], cpu["t"]))
               if (int(seg), float(t)) in at]
    assert len(matched) == len(cpu["t"])
    g, c = zip(*matched)
    np.testing.assert_allclose(gpu["centres"][list(g)], cpu["centres"][list(c)], rtol=0, atol=2e-6)
    with pytest.raises(ValueError, match="'nodes'"):
        wires.Runtime(64, 64, path="rings")


def test_default_path_is_nodes_with_compute_and_cpu_without(monkeypatch, capfd):
    """path='auto' (the default) picks the nodes path where the context has compute and logs the choice in one line;
    with compute missing (forced: WIRE_GL_NO_COMPUTE=1) it picks cpu and still draws the wire."""
    monkeypatch.delenv("WIRE_GL_NO_COMPUTE", raising=False)
    assert wires.Runtime(64, 64).path == "nodes"
    assert "wire: upload path nodes (" in capfd.readouterr().err
    monkeypatch.setenv("WIRE_GL_NO_COMPUTE", "1")
    rt = wires.Runtime(160, 90)
    assert rt.path == "cpu"
    assert "wire: upload path cpu (the nodes path cannot be used: compute shaders disabled" in capfd.readouterr().err
    rt.spawn(hanging(), radius=0.03)
    rt.set_camera((0.0, 0.5, 5.0), (0.0, 0.0, 0.0))
    rt.update()
    image = rt.render(clear=CLEAR)
    background = np.round(np.array(CLEAR[:3]) * 255)
    assert (np.abs(image[:, :, :3].astype(float) - background).max(axis=2) > 24).sum() > 20  # the wire's pixels
    assert wires.Runtime(64, 64, path="nodes").path == "nodes"  # a named path is taken as named


def test_path_gpu_is_a_retired_name_of_nodes():
    """'gpu' named the ring records the CPU built, retired in 0.4: for one release it draws on the nodes path and
    warns; as an error under -W error, like any DeprecationWarning."""
    with pytest.warns(DeprecationWarning, match="'gpu'.*retired"):
        rt = wires.Runtime(64, 64, path="gpu")
    assert rt.path == "nodes"
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        with pytest.raises(DeprecationWarning):
            wires.Runtime(64, 64, path="gpu")


# ---- pixels: the wire is drawn where its nodes project ----

def test_image_shows_the_wire_where_its_nodes_project(tmp_path):
    width, height = 480, 270
    rt = wires.Runtime(width, height)
    blue = rt.add_material((0.4, 0.7, 1.0))
    nodes = hanging(16, 0.2)
    w = rt.spawn(nodes, radius=0.03, material=blue)
    rt.set_camera((0.0, 0.0, 5.0), (0.0, 0.0, 0.0))
    rt.update()
    image = rt.render(clear=CLEAR)
    assert image.shape == (height, width, 4) and image.dtype == np.uint8
    drawn = ~background(image)
    bluish = drawn & (image[..., 2].astype(int) > image[..., 0].astype(int) + 20)
    for x, y, _ in rt.project(nodes):
        xi, yi = int(x), int(y)
        assert bluish[max(yi - 2, 0):yi + 3, max(xi - 2, 0):xi + 3].any(), f"no wire pixel at node ({x:.1f}, {y:.1f})"
    # Nowhere else: the top and bottom fifth are empty.
    assert not drawn[: height // 5].any() and not drawn[height - height // 5:].any()
    # Moved nodes move the picture.
    rt.set_nodes(w, nodes + np.array([0.0, -0.8, 0.0]))
    rt.update()
    moved = ~background(rt.render(clear=CLEAR))
    assert moved[height - height // 5:].any() or moved[int(height * 0.6):].sum() > drawn[int(height * 0.6):].sum()
    png = tmp_path / "wire.png"
    wires.Runtime.save_png(str(png), image)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ---- memory: 1,000 updates of a wire do not grow it ----

def test_a_wire_updated_1000_times_does_not_grow_memory():
    rt = wires.Runtime(320, 180)
    nodes = hanging(64, 0.3)
    w = rt.spawn(nodes, radius=0.02)
    rt.set_camera((0.0, 0.0, 5.0), (0.0, 0.0, 0.0))
    k = np.arange(64)

    def step(i):
        moved = nodes.copy()
        moved[1:-1, 2] += 0.05 * np.sin(0.1 * i + 0.2 * k[1:-1])
        rt.set_nodes(w, moved)
        rt.update()
        if i % 100 == 0:
            rt.render()

    # Warm-up: containers at their working capacity, allocator pools settled. The window starts after 1,500
    # updates. The heap in use, not RSS, is measured: under CPU load (ctest -j2 beside a package build) RSS grew by
    # 4-16 KiB per 100 updates until about update 1,300, and once (a fresh clone's CI) by 528 KiB inside the window,
    # which 7 runs here, 4 of them at once, did not repeat; run alone it is flat over 6,000 updates.
    for i in range(1500):
        step(i)
    systems_before, heap_before = rt.memory(w), heap_in_use_kib()
    for i in range(1500, 2500):
        step(i)
    systems_after, heap_after = rt.memory(w), heap_in_use_kib()
    assert systems_after == systems_before
    # A leak of 256 bytes per update would add 250 KiB; allow half of that for allocator noise.
    assert heap_after - heap_before < 128, f"the heap grew by {heap_after - heap_before} KiB over 1,000 updates"


# ---- many wires in one call ----

def test_set_positions_equals_set_nodes():
    frames = [np.stack([hanging(32, 0.1 + 0.05 * i, z=-0.2 * i) for i in range(5)]) + 0.01 * f for f in range(3)]
    a, b = wires.Runtime(320, 180), wires.Runtime(320, 180)
    wa = [a.spawn(p, radius=0.02) for p in frames[0]]
    wb = [b.spawn(p, radius=0.02) for p in frames[0]]
    for rt in (a, b):
        rt.set_camera((0.0, 0.5, 5.0), (0.0, 0.0, 0.0))
    for positions in frames[1:]:
        a.set_positions(wa, positions)
        for w, p in zip(wb, positions):
            b.set_nodes(w, p)
        a.update()
        b.update()
    np.testing.assert_array_equal(a.render(), b.render())
    for x, y in zip(wa, wb):
        for key, value in a.rings(x).items():
            np.testing.assert_array_equal(value, b.rings(y)[key])


# ---- the README's and docs/python.md's examples run as written ----

def python_block(doc, section):
    """The first ```python block after `section` (a heading line) of the repository's markdown file `doc`."""
    text = (Path(__file__).resolve().parents[2] / doc).read_text()
    part = text[text.index(section + "\n"):]
    begin = part.index("```python\n") + len("```python\n")
    return part[begin:part.index("```", begin)]


def test_readme_python_example_renders_a_wire(tmp_path, monkeypatch):
    code = python_block("README.md", "## Python")
    monkeypatch.chdir(tmp_path)
    scope = {}
    exec(compile(code, "README.md (## Python)", "exec"), scope)
    image = scope["rt"].render()
    assert image.shape == (360, 640, 4)
    drawn = ~background(image)
    assert drawn.sum() > 500  # a 3 m cable 6 cm thick seen from 4 m: about 230 x 5 px
    # Where the nodes project: a drawn pixel within 2 px of each node.
    px = scope["rt"].project(scope["nodes"])
    for x, y in zip(px[:, 0], px[:, 1]):
        xi, yi = int(round(x)), int(round(y))
        assert drawn[max(yi - 2, 0):yi + 3, max(xi - 2, 0):xi + 3].any(), (x, y)
    assert (tmp_path / "cable.png").stat().st_size > 0


def test_docs_python_example_runs(tmp_path, monkeypatch):
    code = python_block("docs/python.md", "## Example")
    monkeypatch.chdir(tmp_path)
    scope = {}
    exec(compile(code, "docs/python.md (## Example)", "exec"), scope)
    assert sorted(p.name for p in tmp_path.glob("rope_*.png")) == [f"rope_{f:04d}.png" for f in (0, 30, 60, 90)]
    rings = scope["rings"]
    assert rings["centres"].shape[1] == 3 and len(rings["u"]) == len(rings["centres"]) >= 2
    assert np.all(np.diff(rings["u"]) > 0)
    # The rope swung down from its horizontal start: its free end is well below the hook.
    assert scope["x"][-1, 1] < 0.0


# ---- one version number: CMakeLists.txt's project(VERSION), the module and the installed wheel ----

def test_version_is_the_projects():
    import re
    from importlib import metadata

    cmake = (Path(__file__).resolve().parents[2] / "CMakeLists.txt").read_text()
    project = re.search(r"project\(wires VERSION ([0-9]+\.[0-9]+\.[0-9]+)", cmake).group(1)
    assert wires.__version__ == project
    try:  # installed by pip (tools/test.sh's pip stage): the wheel's metadata carries the same number
        installed = metadata.version("wires")
    except metadata.PackageNotFoundError:
        installed = None
    if installed is not None:
        assert installed == project


def test_the_module_comes_from_where_it_was_installed():
    """tools/pip_install_test.sh sets WIRES_EXPECTED_PREFIX to its virtual environment: not the build tree."""
    prefix = os.environ.get("WIRES_EXPECTED_PREFIX")
    if prefix is None:
        pytest.skip("WIRES_EXPECTED_PREFIX not set (the build tree's module, ctest python_wires)")
    assert Path(wires.__file__).resolve().is_relative_to(Path(prefix).resolve()), wires.__file__


# ---- the bulk node stream (Runtime.stream_add / stream_nodes) ----

def test_stream_draws_what_spawned_wires_draw():
    """Wires streamed in one call per frame (double, and float32 offsets from origins) draw the picture the same
    nodes draw as spawned ECS wires, frame after frame while they move."""
    rows = np.array([0.0, 0.35, 0.0])[None, None, :] * (np.arange(6)[:, None, None] - 3.0)
    frames = [np.stack([hanging(24, 0.1 + 0.04 * i, z=-0.3 * i) for i in range(6)]) + rows + 0.02 * f
              for f in range(3)]
    a, b, c = (wires.Runtime(320, 180, path="nodes") for _ in range(3))
    spawned = [a.spawn(p, radius=0.05) for p in frames[0]]
    streamed = [b.stream_add(radius=0.05) for _ in range(6)]
    offsets = [c.stream_add(radius=0.05) for _ in range(6)]
    for rt in (a, b, c):
        rt.set_camera((0.0, 0.5, 5.0), (0.0, 0.0, 0.0))
    for positions in frames:
        for w, p in zip(spawned, positions):
            a.set_nodes(w, p)
        a.update()
        b.update()
        c.update()
        assert b.stream_nodes(streamed, positions) == 6
        origins = positions[:, 0, :].astype(np.float32).astype(np.float64)
        assert c.stream_nodes(offsets, (positions - origins[:, None, :]).astype(np.float32), origins) == 6
        want = a.render()
        for rt in (b, c):
            got = rt.render()
            wire_pixels = ~background(want) | ~background(got)
            differ = np.any(np.abs(want[..., :3].astype(int) - got[..., :3].astype(int)) > 24, axis=-1) & wire_pixels
            assert wire_pixels.sum() > 500
            assert differ.sum() <= 0.01 * wire_pixels.sum()


def test_stream_refuses_bad_nodes_naming_wire_and_node_and_draws_the_rest():
    rt = wires.Runtime(320, 180, path="nodes")
    rt.set_camera((0.0, 0.5, 5.0), (0.0, 0.0, 0.0))
    ws = [rt.stream_add(radius=0.03) for _ in range(3)]
    good = np.stack([hanging(16, 0.1 * (i + 1), z=-0.3 * i) for i in range(3)])
    rt.stream_nodes(ws, good)
    rt.update()
    before = rt.render()
    bad = good.copy()
    bad[1, 5, 1] = np.nan
    with pytest.raises(wires.WireError, match=r"stream wire 1: node 5: position\.y is NaN"):
        rt.stream_nodes(ws, bad)
    rt.update()
    after = rt.render()
    # The bad wire keeps its last curve and the others were written (the same nodes): the same picture.
    assert np.abs(before.astype(int) - after.astype(int)).max() <= 2
    with pytest.raises(ValueError, match=r"positions: expected an array of shape \(3, N, 3\)"):
        rt.stream_nodes(ws, good[:2])


def test_stream_needs_the_nodes_path():
    rt = wires.Runtime(64, 64, path="cpu")
    with pytest.raises(ValueError, match="the node stream draws on the 'nodes' path"):
        rt.stream_add()
